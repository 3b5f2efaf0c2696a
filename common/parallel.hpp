#pragma once
// Per-element loops on every core, with results that do not depend on the number of threads.
//
// A finite element loop computes something per element (a rotation, a force, a 12×12 matrix) and
// adds it into global arrays. The adding is where threads would race, and where a parallel sum
// would make the last bits depend on how the elements were split among the threads. So the
// course splits the two: parallel_for computes every element's result into its own slot, and the
// caller adds the slots up afterwards, one element after another in element order. That is the
// same sequence of floating-point operations on 1 thread or 64, so the results are identical to
// the last bit (the scenes runner tests it), and the serial part is only the adding.
// parallel_for_then_add does both halves batch by batch, so that the slots stay in the cache.
//
// OpenMP (g++ -fopenmp, linked through fem_common) runs the loop; OMP_NUM_THREADS sets the number
// of threads. Built without OpenMP, parallel_for is a plain loop.

#include "common/error.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <exception>
#include <utility>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace fem {

/// The number of threads parallel_for runs on (omp_get_max_threads(); 1 without OpenMP).
inline int thread_count()
{
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

/// Sets the number of threads of the next parallel_for loops (omp_set_num_threads), e.g. to
/// measure the speed-up or to check that the results do not change. Ignored without OpenMP.
/// fem::Error for threads < 1.
inline void set_thread_count(int threads)
{
    if (threads < 1)
        throw Error(str("set_thread_count: the number of threads must be >= 1, got ", threads));
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
}

/// Sets the number of threads for one scope and restores the previous number when the scope ends,
/// also by an exception: e.g. `const ScopedThreadCount one_core(1);` around a study timed on one
/// core. fem::Error for threads < 1.
class ScopedThreadCount {
public:
    explicit ScopedThreadCount(int threads) : previous_(thread_count()) { set_thread_count(threads); }
    ~ScopedThreadCount() { set_thread_count(previous_); }
    ScopedThreadCount(const ScopedThreadCount&) = delete;
    ScopedThreadCount& operator=(const ScopedThreadCount&) = delete;

private:
    int previous_;
};

/// Asks the process's BLAS for `threads` threads: OpenBLAS's openblas_set_num_threads(threads),
/// looked up at run time (dlsym), since a BLAS is in the process only when CHOLMOD is (chapters 08
/// and 09; OpenBLAS on Debian, which may start a thread per core) and another BLAS has no such
/// switch. The course's comparisons use 1: one core against our one core. Returns whether the BLAS
/// took it (false: no OpenBLAS in the process, nothing done). fem::Error for threads < 1.
bool set_blas_threads(int threads);

/// Makes OpenMP's threads wait for the next loop asleep instead of spinning, unless the user chose
/// (OMP_WAIT_POLICY set): sets OMP_WAIT_POLICY=passive and starts the program again, the same
/// process (execv of /proc/self/exe with the same argv), since libgomp reads the variable once,
/// when it is loaded, before main(). Why: between two loops a spinning thread keeps its core busy;
/// beside another busy process it competes with it for that core and waits its turn for every loop
/// (chapter 12's element loops on 2 threads took 2.5-30x as long as on 1 beside a spinning process,
/// and 0.6-1.06x with passive waiting; docs/engineering.md, "Threads on a busy machine"). On a
/// quiet machine waking a sleeping thread costs a few microseconds per loop. ChapterCli::run calls it first; it
/// returns at once without OpenMP, when the variable is set, for an argv that is not main()'s own
/// (a test calling ChapterCli::run), or if execv fails (nothing is lost but speed).
void wait_passively(char** argv);

/// Calls body(i) for every i in [0, n), split among thread_count() threads (a static schedule).
/// Each body(i) must write only what belongs to i. An exception thrown by body(i) is rethrown
/// after the loop: the one of the smallest such i, so that a run fails with the same message on
/// any number of threads (an exception may not leave an OpenMP region by itself).
template <class Body>
void parallel_for(Eigen::Index n, Body&& body)
{
    std::vector<std::pair<Eigen::Index, std::exception_ptr>> failures;
#ifdef _OPENMP
#pragma omp parallel for schedule(static)
#endif
    for (Eigen::Index i = 0; i < n; ++i) {
        try {
            body(i);
        } catch (...) {
#ifdef _OPENMP
#pragma omp critical(fem_parallel_for_failures)
#endif
            failures.emplace_back(i, std::current_exception());
        }
    }
    if (failures.empty())
        return;
    std::size_t first = 0;
    for (std::size_t k = 1; k < failures.size(); ++k)
        if (failures[k].first < failures[first].first)
            first = k;
    std::rethrow_exception(failures[first].second);
}

/// The per-element pattern of this header in batches: for each batch of `batch` consecutive
/// elements, compute(i, slot) for every i of the batch on every core (slot: slots[i − first]),
/// then add(i, slot) for each i of the batch in order. The same operations in the same order as
/// parallel_for over all slots followed by one ordered loop, so the same bits on any number of
/// threads; but only batch slots (e.g. 512 12×12 matrices, 0.6 MB) are written and read back, in
/// the cache, instead of one slot per element in memory. On one thread each element is added
/// right after it is computed, in one slot that stays in the fastest cache: compute(i) depends on
/// i alone, so these too are the same operations in the same order. An exception is rethrown as
/// parallel_for does (the smallest i); some of the elements before it have been added by then.
/// fem::Error for batch < 1.
template <class Slot, class Compute, class Add>
void parallel_for_then_add(Eigen::Index n, std::vector<Slot>& slots, Compute&& compute, Add&& add,
                           Eigen::Index batch = 512)
{
    if (batch < 1)
        throw Error(str("parallel_for_then_add: the batch must hold >= 1 element, got ", batch));
    if (thread_count() == 1) {
        if (slots.empty())
            slots.resize(1);
        for (Eigen::Index i = 0; i < n; ++i) {
            compute(i, slots.front());
            add(i, std::as_const(slots.front()));
        }
        return;
    }
    slots.resize(static_cast<std::size_t>(std::max<Eigen::Index>(0, std::min(batch, n))));
    for (Eigen::Index first = 0; first < n; first += batch) {
        const Eigen::Index count = std::min(batch, n - first);
        parallel_for(count, [&](Eigen::Index k) { compute(first + k, slots[static_cast<std::size_t>(k)]); });
        for (Eigen::Index k = 0; k < count; ++k)
            add(first + k, std::as_const(slots[static_cast<std::size_t>(k)]));
    }
}

}  // namespace fem
