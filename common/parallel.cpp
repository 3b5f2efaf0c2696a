#include "common/parallel.hpp"

#include <cstdlib>

#include <unistd.h>

namespace fem {

void wait_passively(char** argv)
{
#ifdef _OPENMP
    if (std::getenv("OMP_WAIT_POLICY") != nullptr)
        return;  // the user's choice, or the restarted program
    if (::setenv("OMP_WAIT_POLICY", "passive", 1) != 0)
        return;
    ::execv("/proc/self/exe", argv);  // returns only if it failed: run on with spinning threads
#else
    (void)argv;
#endif
}

}  // namespace fem
