// Chapter 08: the supernodal Cholesky's dense kernels: C −= A Bᵀ and the substitutions' panel
// products, hand-written for AVX2/FMA and chosen at run time, Eigen's products otherwise.
// docs/08_direct_solvers.md#supernodes-dense-blocks
#include "08_direct_solvers/supernodal_kernels.hpp"

#include "common/simd.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <vector>

#ifdef FEM_AVX2_KERNEL
#include <immintrin.h>
#endif

namespace fem::direct {
namespace {

// --- C −= A Bᵀ, the operation that does almost all the flops --------------------------------
//
// Eigen compiled for baseline x86-64 multiplies with SSE2 (2 doubles per instruction, no fused
// multiply-add). Most machines have AVX2 and FMA (4 doubles, multiply and add in one), so the
// product below has a hand-written kernel for them, chosen at run time, in the classic layout of
// GotoBLAS/BLIS: B is packed in panels of 6 columns of C, A in strips of 8 rows, and an 8×6 block
// of C stays in 12 vector registers while k runs. Without AVX2 the product is Eigen's.

#ifdef FEM_AVX2_KERNEL
constexpr int depth_block = 256, row_block = 96, col_block = 2400;  // what stays in L1 / L2 / L3

/// A 64-byte aligned scratch area that grows as needed (one per thread).
double* scratch(std::vector<double>& storage, std::size_t entries)
{
    if (storage.size() < entries + 8)
        storage.resize(entries + 8);
    const auto address = reinterpret_cast<std::uintptr_t>(storage.data());
    return storage.data() + ((64 - address % 64) % 64) / sizeof(double);
}

/// C(8×6) −= Σ_p a_p b_pᵀ with a packed (8 per p, aligned) and b packed (6 per p). A full tile
/// is updated in place; a partial one (rows × cols) through a small buffer.
__attribute__((target("avx2,fma"))) void kernel_8x6(int k, const double* a, const double* b, double* C, int ldc,
                                                    int rows, int cols)
{
    __m256d c0a = _mm256_setzero_pd(), c0b = _mm256_setzero_pd(), c1a = _mm256_setzero_pd(),
            c1b = _mm256_setzero_pd(), c2a = _mm256_setzero_pd(), c2b = _mm256_setzero_pd(),
            c3a = _mm256_setzero_pd(), c3b = _mm256_setzero_pd(), c4a = _mm256_setzero_pd(),
            c4b = _mm256_setzero_pd(), c5a = _mm256_setzero_pd(), c5b = _mm256_setzero_pd();
    for (int p = 0; p < k; ++p) {
        const __m256d a0 = _mm256_load_pd(a), a1 = _mm256_load_pd(a + 4);
        __m256d bj = _mm256_broadcast_sd(b);
        c0a = _mm256_fmadd_pd(a0, bj, c0a);
        c0b = _mm256_fmadd_pd(a1, bj, c0b);
        bj = _mm256_broadcast_sd(b + 1);
        c1a = _mm256_fmadd_pd(a0, bj, c1a);
        c1b = _mm256_fmadd_pd(a1, bj, c1b);
        bj = _mm256_broadcast_sd(b + 2);
        c2a = _mm256_fmadd_pd(a0, bj, c2a);
        c2b = _mm256_fmadd_pd(a1, bj, c2b);
        bj = _mm256_broadcast_sd(b + 3);
        c3a = _mm256_fmadd_pd(a0, bj, c3a);
        c3b = _mm256_fmadd_pd(a1, bj, c3b);
        bj = _mm256_broadcast_sd(b + 4);
        c4a = _mm256_fmadd_pd(a0, bj, c4a);
        c4b = _mm256_fmadd_pd(a1, bj, c4b);
        bj = _mm256_broadcast_sd(b + 5);
        c5a = _mm256_fmadd_pd(a0, bj, c5a);
        c5b = _mm256_fmadd_pd(a1, bj, c5b);
        a += kernel_rows;
        b += kernel_cols;
    }
    const __m256d sums[kernel_cols][2] = {{c0a, c0b}, {c1a, c1b}, {c2a, c2b}, {c3a, c3b}, {c4a, c4b}, {c5a, c5b}};
    if (rows == kernel_rows && cols == kernel_cols) {
        for (int j = 0; j < kernel_cols; ++j) {
            double* const column = C + static_cast<long long>(j) * ldc;
            _mm256_storeu_pd(column, _mm256_sub_pd(_mm256_loadu_pd(column), sums[j][0]));
            _mm256_storeu_pd(column + 4, _mm256_sub_pd(_mm256_loadu_pd(column + 4), sums[j][1]));
        }
        return;
    }
    alignas(32) double tile[kernel_rows * kernel_cols];
    for (int j = 0; j < kernel_cols; ++j) {
        _mm256_store_pd(tile + kernel_rows * j, sums[j][0]);
        _mm256_store_pd(tile + kernel_rows * j + 4, sums[j][1]);
    }
    for (int j = 0; j < cols; ++j)
        for (int i = 0; i < rows; ++i)
            C[i + static_cast<long long>(j) * ldc] -= tile[i + kernel_rows * j];
}

/// The packed, blocked C −= A Bᵀ (all column-major).
__attribute__((target("avx2,fma"))) void subtract_product_avx2(int m, int n, int k, const double* A, int lda,
                                                               const double* B, int ldb, double* C, int ldc)
{
    thread_local std::vector<double> a_storage, b_storage;
    for (int jc = 0; jc < n; jc += col_block) {
        const int nb = std::min(col_block, n - jc);
        const int n_strips = (nb + kernel_cols - 1) / kernel_cols;
        for (int pc = 0; pc < k; pc += depth_block) {
            const int kb = std::min(depth_block, k - pc);
            // B's rows jc … jc+nb−1, columns pc … pc+kb−1, in strips of 6: b[strip][p][0..5]
            double* const b_packed = scratch(b_storage, static_cast<std::size_t>(n_strips) * kernel_cols * kb);
            for (int s = 0; s < n_strips; ++s) {
                const int j0 = jc + s * kernel_cols, width = std::min(kernel_cols, n - j0);
                double* out = b_packed + static_cast<std::size_t>(s) * kernel_cols * kb;
                for (int p = 0; p < kb; ++p, out += kernel_cols) {
                    const double* column = B + j0 + static_cast<long long>(pc + p) * ldb;
                    for (int j = 0; j < width; ++j)
                        out[j] = column[j];
                    for (int j = width; j < kernel_cols; ++j)
                        out[j] = 0.0;
                }
            }
            for (int ic = 0; ic < m; ic += row_block) {
                const int mb = std::min(row_block, m - ic);
                const int m_strips = (mb + kernel_rows - 1) / kernel_rows;
                double* const a_packed = scratch(a_storage, static_cast<std::size_t>(m_strips) * kernel_rows * kb);
                for (int s = 0; s < m_strips; ++s) {
                    const int i0 = ic + s * kernel_rows, height = std::min(kernel_rows, m - i0);
                    double* out = a_packed + static_cast<std::size_t>(s) * kernel_rows * kb;
                    for (int p = 0; p < kb; ++p, out += kernel_rows) {
                        const double* column = A + i0 + static_cast<long long>(pc + p) * lda;
                        for (int i = 0; i < height; ++i)
                            out[i] = column[i];
                        for (int i = height; i < kernel_rows; ++i)
                            out[i] = 0.0;
                    }
                }
                for (int sj = 0; sj < n_strips; ++sj) {
                    const int j0 = jc + sj * kernel_cols, cols = std::min(kernel_cols, n - j0);
                    const double* const b = b_packed + static_cast<std::size_t>(sj) * kernel_cols * kb;
                    for (int si = 0; si < m_strips; ++si) {
                        const int i0 = ic + si * kernel_rows, rows = std::min(kernel_rows, m - i0);
                        kernel_8x6(kb, a_packed + static_cast<std::size_t>(si) * kernel_rows * kb, b,
                                   C + i0 + static_cast<long long>(j0) * ldc, ldc, rows, cols);
                    }
                }
            }
        }
    }
}
#endif

#ifdef FEM_AVX2_KERNEL
// --- the substitutions' matrix-vector products -------------------------------------------------
//
// A triangular solve reads every stored entry of L once and does one multiply-add with it, so it
// runs at the speed memory delivers L. Eigen's baseline SSE2 products fall short of that speed;
// the two AVX2 kernels below (8 floats or 4 doubles per fused multiply-add, four columns of L per
// pass over the short vector) reach it. Chosen at run time, like the product kernel above.

/// The AVX2 register of one scalar type (8 floats or 4 doubles) and what the kernels do with it:
/// each operation once, its float and double intrinsics side by side.
template <class Scalar>
struct Avx2Register;
template <>
struct Avx2Register<float> { using type = __m256; };
template <>
struct Avx2Register<double> { using type = __m256d; };

template <class Scalar>
struct Avx2Lanes {
    static constexpr bool single = std::is_same_v<Scalar, float>;
    using Register = typename Avx2Register<Scalar>::type;
    static constexpr int width = 32 / sizeof(Scalar);
    __attribute__((target("avx2,fma"))) static Register zero()
    {
        if constexpr (single) return _mm256_setzero_ps(); else return _mm256_setzero_pd();
    }
    __attribute__((target("avx2,fma"))) static Register load(const Scalar* p)
    {
        if constexpr (single) return _mm256_loadu_ps(p); else return _mm256_loadu_pd(p);
    }
    __attribute__((target("avx2,fma"))) static void store(Scalar* p, Register v)
    {
        if constexpr (single) _mm256_storeu_ps(p, v); else _mm256_storeu_pd(p, v);
    }
    __attribute__((target("avx2,fma"))) static Register broadcast(Scalar x)
    {
        if constexpr (single) return _mm256_set1_ps(x); else return _mm256_set1_pd(x);
    }
    __attribute__((target("avx2,fma"))) static Register fma(Register a, Register b, Register c)
    {
        if constexpr (single) return _mm256_fmadd_ps(a, b, c); else return _mm256_fmadd_pd(a, b, c);
    }
    __attribute__((target("avx2,fma"))) static Scalar sum(Register v)
    {
        if constexpr (single) {
            const __m128 half = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
            const __m128 quarter = _mm_add_ps(half, _mm_movehl_ps(half, half));
            return _mm_cvtss_f32(_mm_add_ss(quarter, _mm_shuffle_ps(quarter, quarter, 1)));
        } else {
            const __m128d half = _mm_add_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
            return _mm_cvtsd_f64(_mm_add_sd(half, _mm_unpackhi_pd(half, half)));
        }
    }
};

/// t −= B x for a column-major B (r×4, leading dimension ld): the four columns in one pass over t.
template <class Scalar>
__attribute__((target("avx2,fma"))) void subtract_product_avx2(int r, const Scalar* B, long long ld, const Scalar* x,
                                                               Scalar* t)
{
    using Lanes = Avx2Lanes<Scalar>;
    constexpr int w = Lanes::width;
    const Scalar *const b0 = B, *const b1 = b0 + ld, *const b2 = b1 + ld, *const b3 = b2 + ld;
    const auto x0 = Lanes::broadcast(-x[0]), x1 = Lanes::broadcast(-x[1]), x2 = Lanes::broadcast(-x[2]),
               x3 = Lanes::broadcast(-x[3]);
    int i = 0;
    for (; i + w <= r; i += w) {
        auto sum = Lanes::fma(Lanes::load(b0 + i), x0, Lanes::load(t + i));
        sum = Lanes::fma(Lanes::load(b1 + i), x1, sum);
        sum = Lanes::fma(Lanes::load(b2 + i), x2, sum);
        Lanes::store(t + i, Lanes::fma(Lanes::load(b3 + i), x3, sum));
    }
    for (; i < r; ++i)
        t[i] -= b0[i] * x[0] + b1[i] * x[1] + b2[i] * x[2] + b3[i] * x[3];
}

/// x −= Bᵀ t for a column-major B (r×4, leading dimension ld): four dot products in one pass over t.
template <class Scalar>
__attribute__((target("avx2,fma"))) void subtract_transposed_product_avx2(int r, const Scalar* B, long long ld,
                                                                          const Scalar* t, Scalar* x)
{
    using Lanes = Avx2Lanes<Scalar>;
    constexpr int w = Lanes::width;
    const Scalar *const b0 = B, *const b1 = b0 + ld, *const b2 = b1 + ld, *const b3 = b2 + ld;
    auto s0 = Lanes::zero(), s1 = Lanes::zero(), s2 = Lanes::zero(), s3 = Lanes::zero();
    int i = 0;
    for (; i + w <= r; i += w) {
        const auto ti = Lanes::load(t + i);
        s0 = Lanes::fma(Lanes::load(b0 + i), ti, s0);
        s1 = Lanes::fma(Lanes::load(b1 + i), ti, s1);
        s2 = Lanes::fma(Lanes::load(b2 + i), ti, s2);
        s3 = Lanes::fma(Lanes::load(b3 + i), ti, s3);
    }
    Scalar d0 = Lanes::sum(s0), d1 = Lanes::sum(s1), d2 = Lanes::sum(s2), d3 = Lanes::sum(s3);
    for (; i < r; ++i) {
        d0 += b0[i] * t[i];
        d1 += b1[i] * t[i];
        d2 += b2[i] * t[i];
        d3 += b3[i] * t[i];
    }
    x[0] -= d0;
    x[1] -= d1;
    x[2] -= d2;
    x[3] -= d3;
}
#endif

}  // namespace

template <bool transposed, class Scalar>
void subtract_panel_product(int r, int c, const Scalar* B, int ld, const Scalar* in, Scalar* out)
{
#ifdef FEM_AVX2_KERNEL
    if (c == 4 && avx2_enabled()) {
        if constexpr (transposed)
            subtract_transposed_product_avx2(r, B, ld, in, out);
        else
            subtract_product_avx2(r, B, ld, in, out);
        return;
    }
#endif
    using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
    using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
    const Eigen::Map<const Matrix, 0, Eigen::OuterStride<>> panel(B, r, c, Eigen::OuterStride<>(ld));
    if constexpr (transposed)
        Eigen::Map<Vector>(out, c).noalias() -= panel.transpose() * Eigen::Map<const Vector>(in, r);
    else
        Eigen::Map<Vector>(out, r).noalias() -= panel * Eigen::Map<const Vector>(in, c);
}

void subtract_product(int m, int n, int k, const double* A, int lda, const double* B, int ldb, double* C, int ldc)
{
    if (m == 0 || n == 0 || k == 0)
        return;
#ifdef FEM_AVX2_KERNEL
    if (avx2_enabled() && m >= kernel_rows && n >= kernel_cols) {
        subtract_product_avx2(m, n, k, A, lda, B, ldb, C, ldc);
        return;
    }
#endif
    // Eigen's product on one thread, asked for explicitly: `C −= A Bᵀ` through Eigen's expressions
    // runs Eigen's own OpenMP GEMM when called outside a parallel region (the top's products), and
    // that GEMM chooses its blocking, so possibly the order of the sums, by the number of threads.
    using Eigen::ColMajor, Eigen::Dynamic, Eigen::RowMajor;
    Eigen::internal::gemm_blocking_space<ColMajor, double, double, Dynamic, Dynamic, Dynamic> blocking(m, n, k, 1, true);
    Eigen::internal::general_matrix_matrix_product<Eigen::Index, double, ColMajor, false, double, RowMajor, false,
                                                   ColMajor, 1>::run(m, n, k, A, lda, B, ldb, C, 1, ldc, -1.0,
                                                                     blocking, nullptr);
}

template void subtract_panel_product<false, float>(int, int, const float*, int, const float*, float*);
template void subtract_panel_product<true, float>(int, int, const float*, int, const float*, float*);
template void subtract_panel_product<false, double>(int, int, const double*, int, const double*, double*);
template void subtract_panel_product<true, double>(int, int, const double*, int, const double*, double*);

}  // namespace fem::direct
