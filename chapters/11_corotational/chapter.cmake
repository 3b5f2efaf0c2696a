# The executable's studies, one file each (studies.hpp); not part of the chapter's library.
target_sources(${exe} PRIVATE
  ${FEM_ROOT}/chapters/11_corotational/study_common.cpp ${FEM_ROOT}/chapters/11_corotational/study_rotations.cpp
  ${FEM_ROOT}/chapters/11_corotational/study_swing.cpp ${FEM_ROOT}/chapters/11_corotational/study_cost.cpp)

# The unit tests once more with FEM_NO_AVX2=1: the polar rotations one tet at a time.
fem_test_without_avx2(11 "${test_exe}")
