#pragma once
// Whether the hand-written AVX2 kernels run (chapter 08's dense products and substitutions, chapter
// 11's polar rotations four tets at a time).
//
// The course compiles for baseline x86-64 (SSE2), so that one build runs on any x86 machine; a
// kernel for AVX2 and FMA is compiled on its own (__attribute__((target("avx2,fma")))) and chosen
// at run time. FEM_NO_AVX2=1 in the environment turns them all off, as on a machine without
// AVX2: to test that path (ctest runs chapter 08's and 11's tests both ways) and to see what the
// kernels change. docs/08_direct_solvers.md#supernodes-dense-blocks

#include <cstdlib>
#include <string_view>

namespace fem {

/// True when the processor has AVX2 and FMA and the environment variable FEM_NO_AVX2 is unset,
/// empty or "0" (read once).
inline bool avx2_enabled()
{
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    static const bool enabled = [] {
        const char* off = std::getenv("FEM_NO_AVX2");
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
               (off == nullptr || std::string_view(off).empty() || std::string_view(off) == "0");
    }();
    return enabled;
#else
    return false;
#endif
}

}  // namespace fem
