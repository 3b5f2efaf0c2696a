#pragma once
// Chapter 08: the dense kernels of the supernodal Cholesky (supernodal.cpp): the product
// C −= A Bᵀ that does almost all the flops of a factorization, and the panel products of the
// substitutions. Each has a hand-written AVX2/FMA kernel, chosen at run time (common/simd.hpp),
// and Eigen's product otherwise. docs/08_direct_solvers.md#supernodes-dense-blocks

// The kernels are compiled where the compiler offers the x86 intrinsics (GCC, clang on x86).
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define FEM_AVX2_KERNEL 1
#endif

namespace fem::direct {

/// The register block of C in the AVX2 product kernel: kernel_rows × kernel_cols entries stay in
/// vector registers while k runs. A product split among threads in whole blocks of columns keeps
/// every entry's operations those of the whole product.
constexpr int kernel_rows = 8, kernel_cols = 6;

/// C −= A Bᵀ for column-major C (m×n, leading dimension ldc), A (m×k, lda) and B (n×k, ldb). The
/// AVX2 kernel when it runs and m ≥ kernel_rows, n ≥ kernel_cols; Eigen's product on one thread
/// otherwise. Nothing happens when m, n or k is 0.
void subtract_product(int m, int n, int k, const double* A, int lda, const double* B, int ldb, double* C, int ldc);

/// The substitutions' update with the panel columns B (column-major r×c, c ≤ 4, leading
/// dimension ld): forward, out (r) −= B in (c); backward (transposed), out (c) −= Bᵀ in (r). The
/// AVX2 kernel for four columns where it runs; Eigen's product otherwise (and for a supernode's
/// last one to three columns). Scalar: float or double.
template <bool transposed, class Scalar>
void subtract_panel_product(int r, int c, const Scalar* B, int ld, const Scalar* in, Scalar* out);

}  // namespace fem::direct
