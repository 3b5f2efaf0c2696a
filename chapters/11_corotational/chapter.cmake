# The executable's studies, one file each (studies.hpp); not part of the chapter's library.
target_sources(${exe} PRIVATE
  ${FEM_ROOT}/chapters/11_corotational/study_common.cpp ${FEM_ROOT}/chapters/11_corotational/study_rotations.cpp
  ${FEM_ROOT}/chapters/11_corotational/study_swing.cpp ${FEM_ROOT}/chapters/11_corotational/study_cost.cpp
  ${FEM_ROOT}/chapters/11_corotational/plain_routes.cpp)

# The plain route the cost study compares with (plain_routes.hpp) is tested too: its test file
# holds it to our step.
if(test_exe)
  target_sources(${test_exe}_objects PRIVATE ${FEM_ROOT}/chapters/11_corotational/plain_routes.cpp)
endif()

# The unit tests once more with FEM_NO_AVX2=1: the polar rotations one tet at a time.
fem_test_without_avx2(11 "${test_exe}")
