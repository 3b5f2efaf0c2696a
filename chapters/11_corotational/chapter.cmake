# The executable's studies, one file each (studies.hpp); not part of the chapter's library.
target_sources(${exe} PRIVATE
  ${FEM_ROOT}/chapters/11_corotational/study_common.cpp ${FEM_ROOT}/chapters/11_corotational/study_rotations.cpp
  ${FEM_ROOT}/chapters/11_corotational/study_swing.cpp ${FEM_ROOT}/chapters/11_corotational/study_cost.cpp)

# The unit tests once more with the AVX2 polar rotations off (FEM_NO_AVX2=1), the path a processor
# without AVX2 and FMA takes, which this machine would otherwise never run.
if(FEM_BUILD_TESTS)
  add_test(NAME ch11_without_avx2 COMMAND ${test_exe} --warn NoTests)
  set_tests_properties(ch11_without_avx2 PROPERTIES ENVIRONMENT FEM_NO_AVX2=1 LABELS "ch11")
endif()
