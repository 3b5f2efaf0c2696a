# The executable's studies, one file each (studies.hpp); not part of the chapter's library.
target_sources(${exe} PRIVATE
  ${FEM_ROOT}/chapters/14_contact/study_drop.cpp ${FEM_ROOT}/chapters/14_contact/study_slope.cpp
  ${FEM_ROOT}/chapters/14_contact/study_mesh.cpp ${FEM_ROOT}/chapters/14_contact/study_bowl.cpp)
