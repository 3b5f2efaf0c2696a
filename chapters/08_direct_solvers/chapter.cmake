# Chapter 08's executable compares our sparse Cholesky with CHOLMOD's supernodal one (through
# Eigen's CholmodSupport) when SuiteSparse is installed (Debian: libsuitesparse-dev). Optional:
# without it the executable prints "CHOLMOD not installed" rows. Included by fem_add_chapter.
find_path(FEM_CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(FEM_CHOLMOD_LIBRARY cholmod)
if(FEM_CHOLMOD_INCLUDE_DIR AND FEM_CHOLMOD_LIBRARY)
  message(STATUS "Chapter 08: CHOLMOD found (${FEM_CHOLMOD_LIBRARY}); ch08 compares against it")
  target_include_directories(${exe} SYSTEM PRIVATE ${FEM_CHOLMOD_INCLUDE_DIR})
  # dlsym finds OpenBLAS's thread setting at run time, if CHOLMOD's BLAS is OpenBLAS.
  target_link_libraries(${exe} PRIVATE ${FEM_CHOLMOD_LIBRARY} ${CMAKE_DL_LIBS})
  target_compile_definitions(${exe} PRIVATE FEM_HAVE_CHOLMOD)
else()
  message(STATUS "Chapter 08: CHOLMOD not found; ch08 runs without the CHOLMOD reference")
endif()

# The unit tests once more on Eigen's products instead of the AVX2 kernels (FEM_NO_AVX2=1), the
# path a processor without AVX2 and FMA takes, which this machine would otherwise never run.
if(FEM_BUILD_TESTS)
  add_test(NAME ch08_without_avx2 COMMAND ${test_exe} --warn NoTests)
  set_tests_properties(ch08_without_avx2 PROPERTIES ENVIRONMENT FEM_NO_AVX2=1 LABELS "ch08")
endif()
