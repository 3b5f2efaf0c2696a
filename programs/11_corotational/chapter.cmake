# The unit tests once more with FEM_NO_AVX2=1: the polar rotations one tet at a time.
fem_test_without_avx2(11 "${test_exe}")
