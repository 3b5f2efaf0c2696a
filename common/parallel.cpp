#include "common/parallel.hpp"

#include <cerrno>  // program_invocation_name (GNU)
#include <cstdlib>

#include <dlfcn.h>
#include <unistd.h>

namespace fem {

bool set_blas_threads(int threads)
{
    if (threads < 1)
        throw Error(str("set_blas_threads: needs at least 1 thread, got ", threads));
    using SetThreads = void (*)(int);
    if (void* symbol = dlsym(RTLD_DEFAULT, "openblas_set_num_threads")) {
        reinterpret_cast<SetThreads>(symbol)(threads);
        return true;
    }
    return false;
}

void wait_passively(char** argv)
{
#ifdef _OPENMP
    if (std::getenv("OMP_WAIT_POLICY") != nullptr)
        return;  // the user's choice, or the restarted program
    // Only main()'s own argv (its argv[0] is the C library's program_invocation_name) ends with the
    // nullptr execv needs, and only a program's main may start it again: a test that calls
    // ChapterCli::run with an argv of its own must not restart the test.
    if (argv == nullptr || argv[0] != program_invocation_name)
        return;
    if (::setenv("OMP_WAIT_POLICY", "passive", 1) != 0)
        return;
    ::execv("/proc/self/exe", argv);  // returns only if it failed: run on with spinning threads
#else
    (void)argv;
#endif
}

}  // namespace fem
