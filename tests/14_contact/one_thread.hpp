#pragma once
// Chapter 14's and 15's tests run their loops on one thread (included by a test file of each binary:
// it sets the thread count once, before main()). Their bodies are a few to a few hundred
// tets, where OpenMP's threads cost more than they save, and beside another busy process a spinning
// thread makes every loop wait its turn for a core (docs/engineering.md, "Threads on a busy
// machine"): on the course's 2-core machine beside other builds, [ex14.2]'s tagged tests took 160 s
// on 2 threads and 2.2 s on one, [ex15.4]'s 58 s and 4.1 s. A test that checks thread counts sets its
// own (ScopedThreadCount), which this does not change. docs/14_contact.md#checks

#include "common/parallel.hpp"

namespace fem::test {

/// set_thread_count(1), done before main() by the variable's initialisation (once per program).
inline const bool one_thread = [] {
    set_thread_count(1);
    return true;
}();

}  // namespace fem::test
