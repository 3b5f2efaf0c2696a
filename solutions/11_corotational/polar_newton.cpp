// The fast polar rotation: Newton's iteration X ← ½(ζX + (ζX)⁻ᵀ), one matrix or four at a time in
// AVX2 registers (polar_rotation_newton, polar_rotations_newton). Speed only: the rotation is
// polar_rotation's (exercise 11.3, rotations.cpp) to round-off. docs/11_corotational.md#a-faster-polar-decomposition
#include "11_corotational/corotational.hpp"

#include "common/error.hpp"
#include "common/simd.hpp"

#include <algorithm>
#include <cmath>

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#endif

namespace fem::corot {
namespace {

// --- Newton's polar iteration, one matrix or four at a time -------------------------------------
//
// The arithmetic of a step is written once, for lanes T: a double, or four doubles in an AVX2
// register (GCC's vector extension). Entry by entry, in the same order, so four matrices at a time
// give the bits of one at a time. X is held as its 9 entries, column-major (X(i, j) = x[3 j + i]).

// (Results come back through references: a function returning an AVX2 register by value would
// have another calling convention when compiled for baseline x86-64.)

/// The cofactors of X (column c: the cross product of columns c + 1 and c + 2, so that
/// cofactors / det X = X⁻ᵀ) into cof, and det X = column 0 · cof column 0.
template <class T>
[[gnu::always_inline]] inline void cofactors_and_determinant(const T (&x)[9], T (&cof)[9], T& det)
{
    for (int c = 0; c < 3; ++c) {
        const T* a = x + 3 * ((c + 1) % 3);
        const T* b = x + 3 * ((c + 2) % 3);
        cof[3 * c + 0] = a[1] * b[2] - a[2] * b[1];
        cof[3 * c + 1] = a[2] * b[0] - a[0] * b[2];
        cof[3 * c + 2] = a[0] * b[1] - a[1] * b[0];
    }
    det = x[0] * cof[0] + x[1] * cof[1] + x[2] * cof[2];
}

/// sum = ‖X‖² (the entries' squares summed in order).
template <class T>
[[gnu::always_inline]] inline void squared_norm(const T (&x)[9], T& sum)
{
    sum = x[0] * x[0];
    for (int e = 1; e < 9; ++e)
        sum += x[e] * x[e];
}

/// One Newton step: x ← ½(ζ X + s cof) with s = 1/(ζ det X) (one division for all nine entries),
/// and change_squared = ‖X_{k+1} − X_k‖² (no square root: it is compared with squared thresholds).
template <class T>
[[gnu::always_inline]] inline void newton_polar_step(T (&x)[9], const T (&cof)[9], const T& zeta, const T& scale,
                                                     T& change_squared)
{
    T next = 0.5 * (zeta * x[0] + scale * cof[0]);
    change_squared = (next - x[0]) * (next - x[0]);
    x[0] = next;
    for (int e = 1; e < 9; ++e) {
        next = 0.5 * (zeta * x[e] + scale * cof[e]);
        change_squared += (next - x[e]) * (next - x[e]);
        x[e] = next;
    }
}

// The thresholds of polar_rotation_newton (see its comment in the header).
constexpr double flat_fraction = 1e-6;      // det F ≤ this · ‖F‖³: the SVD instead
constexpr double scaling_window = 1e-2;     // ζ = |det X|^(−1/3) while |det X − 1| exceeds this ...
constexpr double scaled_change = 1e-4;      // ... and no step has changed X by less than 1e-2 (squared)
constexpr double converged_change = 1e-16;  // a step's change below 1e-8 (squared): converged
constexpr int newton_step_cap = 40;

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define FEM_AVX2_POLAR 1
using Lanes = double __attribute__((vector_size(32)));     // four doubles in an AVX2 register
using LaneMask = long long __attribute__((vector_size(32)));  // what comparing two Lanes gives

__attribute__((target("avx2,fma"))) bool any_lane(LaneMask mask)
{
    return (mask[0] | mask[1] | mask[2] | mask[3]) != 0;
}

/// polar_rotation_newton of four finite F at once (lane l: F[l]), each step of each lane the same
/// operations as polar_rotation_newton's: the same R, bit for bit. Returns false, leaving the four to
/// the caller, when a lane needs what the lanes do not do: the SVD (det F ≤ 10⁻⁶ ‖F‖³, or 40 steps)
/// or a scaled step (a cube root).
__attribute__((target("avx2,fma"))) bool polar_rotations_newton_avx2(const Eigen::Matrix3d* F, Eigen::Matrix3d* R)
{
    Lanes x[9], cof[9];
    for (int e = 0; e < 9; ++e)
        x[e] = Lanes{F[0].data()[e], F[1].data()[e], F[2].data()[e], F[3].data()[e]};
    Lanes det, size_squared, change_squared;
    cofactors_and_determinant(x, cof, det);
    squared_norm(x, size_squared);
    if (any_lane(!(det > flat_fraction * size_squared * Lanes(_mm256_sqrt_pd(__m256d(size_squared))))))
        return false;
    const Lanes one = {1.0, 1.0, 1.0, 1.0};
    LaneMask scaled = {-1, -1, -1, -1}, done = {0, 0, 0, 0};
    for (int step = 0; step < newton_step_cap; ++step) {
        if (step > 0)
            cofactors_and_determinant(x, cof, det);
        if (any_lane(scaled & ~done & ((det - 1.0 > scaling_window) | (det - 1.0 < -scaling_window))))
            return false;
        const Lanes scale = 1.0 / (one * det);
        newton_polar_step(x, cof, one, scale, change_squared);
        scaled &= !(change_squared < scaled_change);
        const LaneMask converged = (change_squared < converged_change) & ~done;
        for (int l = 0; l < 4; ++l)
            if (converged[l])
                for (int e = 0; e < 9; ++e)
                    R[l].data()[e] = x[e][l];
        done |= converged;
        if (!any_lane(~done))
            return true;
    }
    return false;
}
#endif

}  // namespace

Eigen::Matrix3d polar_rotation_newton(const Eigen::Matrix3d& F)
{
    if (!F.allFinite())
        throw Error("polar rotation: F has a non-finite entry");
    double x[9], cof[9], det = 0.0, size_squared = 0.0, change_squared = 0.0;
    std::copy(F.data(), F.data() + 9, x);
    cofactors_and_determinant(x, cof, det);
    squared_norm(x, size_squared);
    if (!(det > flat_fraction * size_squared * std::sqrt(size_squared)))
        return polar_rotation(F);  // inverted, flat or zero: the SVD and its reflection fix
    bool scaled = true;
    for (int step = 0; step < newton_step_cap; ++step) {
        if (step > 0)
            cofactors_and_determinant(x, cof, det);
        // Scaling pays where the singular values are far from 1; near det = 1 it would only cost a
        // cube root. One division a step: X⁻ᵀ/ζ = cofactors · (1/(ζ det)).
        const double zeta =
            scaled && std::abs(det - 1.0) > scaling_window ? std::cbrt(1.0 / std::abs(det)) : 1.0;
        newton_polar_step(x, cof, zeta, 1.0 / (zeta * det), change_squared);
        if (change_squared < scaled_change)
            scaled = false;  // a change below 1e-2, near orthogonal: plain Newton converges quadratically
        if (change_squared < converged_change)
            return Eigen::Map<const Eigen::Matrix3d>(x);  // X's error is about change² / 2: round-off
    }
    return polar_rotation(F);
}

void polar_rotations_newton(const Eigen::Matrix3d* F, Eigen::Matrix3d* R, std::size_t count)
{
    for (std::size_t k = 0; k < count; ++k)
        if (!F[k].allFinite())
            throw Error(str("polar rotations: F[", k, "] of ", count, " has a non-finite entry (every entry must be finite)"));
    std::size_t first = 0;
#ifdef FEM_AVX2_POLAR
    if (avx2_enabled())
        for (; first + 4 <= count; first += 4) {
            if (polar_rotations_newton_avx2(F + first, R + first))
                continue;
            for (std::size_t k = first; k < first + 4; ++k)
                R[k] = polar_rotation_newton(F[k]);
        }
#endif
    for (; first < count; ++first)
        R[first] = polar_rotation_newton(F[first]);
}

}  // namespace fem::corot
