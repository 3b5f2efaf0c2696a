#include "common/interrupt.hpp"

#include <csignal>

namespace fem {

namespace {

volatile std::sig_atomic_t stop = 0;
volatile std::sig_atomic_t signal_number = 0;

constexpr int stop_signals[] = {SIGINT, SIGTERM, SIGHUP};

extern "C" void on_stop_signal(int signal)
{
    stop = 1;
    signal_number = signal;
    std::signal(signal, SIG_DFL);  // a second one stops at once
}

}  // namespace

void catch_stop_signals()
{
    stop = 0;
    signal_number = 0;
    for (const int signal : stop_signals)
        std::signal(signal, on_stop_signal);
}

bool stop_requested() { return stop != 0; }

void request_stop() { stop = 1; }

int stop_signal() { return signal_number; }

}  // namespace fem
