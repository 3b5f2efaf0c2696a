# The executable's studies, one file each (studies.hpp); not part of the chapter's library.
target_sources(${exe} PRIVATE
  ${FEM_ROOT}/chapters/13_skinning/study_common.cpp ${FEM_ROOT}/chapters/13_skinning/study_location.cpp
  ${FEM_ROOT}/chapters/13_skinning/study_outside.cpp ${FEM_ROOT}/chapters/13_skinning/study_simulation.cpp)
