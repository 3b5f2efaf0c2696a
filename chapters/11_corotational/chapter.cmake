# The executable's studies, one file each (studies.hpp); not part of the chapter's library.
target_sources(${exe} PRIVATE
  ${FEM_ROOT}/chapters/11_corotational/study_common.cpp ${FEM_ROOT}/chapters/11_corotational/study_rotations.cpp
  ${FEM_ROOT}/chapters/11_corotational/study_swing.cpp ${FEM_ROOT}/chapters/11_corotational/study_cost.cpp)
