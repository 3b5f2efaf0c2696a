# Chapter 08's executable compares our sparse Cholesky with CHOLMOD's supernodal one (through
# Eigen's CholmodSupport) when SuiteSparse is installed (Debian: libsuitesparse-dev). Optional:
# without it the executable prints "CHOLMOD not installed" rows. Included by fem_add_chapter.
find_path(FEM_CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(FEM_CHOLMOD_LIBRARY cholmod)
if(FEM_CHOLMOD_INCLUDE_DIR AND FEM_CHOLMOD_LIBRARY)
  message(STATUS "Chapter 08: CHOLMOD found (${FEM_CHOLMOD_LIBRARY}); ch08 compares against it")
  target_include_directories(${exe} SYSTEM PRIVATE ${FEM_CHOLMOD_INCLUDE_DIR})
  # dlsym finds the BLAS's dgemm at run time (study_speed.cpp).
  target_link_libraries(${exe} PRIVATE ${FEM_CHOLMOD_LIBRARY} ${CMAKE_DL_LIBS})
  target_compile_definitions(${exe} PRIVATE FEM_HAVE_CHOLMOD)
else()
  message(STATUS "Chapter 08: CHOLMOD not found; ch08 runs without the CHOLMOD reference")
endif()

# The unit tests once more with FEM_NO_AVX2=1: Eigen's products instead of the AVX2 kernels.
fem_test_without_avx2(08 "${test_exe}")
