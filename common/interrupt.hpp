#pragma once
// Stopping a long run cleanly: SIGINT (Ctrl-C), SIGTERM (kill, timeout) and SIGHUP (the terminal
// closed) ask the run to stop after the step it is in, so that the files written so far are
// published whole (a valid .pvd); a second signal stops the process at once, as usual. The run
// polls stop_requested() between steps, and the executable exits with 128 + stop_signal(), the
// code a shell expects of a process stopped by that signal (130 for SIGINT, 143 for SIGTERM).

namespace fem {

/// Installs the handlers of SIGINT, SIGTERM and SIGHUP and clears an earlier request. Each handler
/// records its signal and puts back the default action, so a second signal ends the process.
void catch_stop_signals();

/// True once a stop signal arrived or request_stop() was called (since catch_stop_signals()).
bool stop_requested();

/// Asks the run to stop as a signal would, without one (e.g. a live view's "quit" key):
/// stop_requested() becomes true, stop_signal() stays 0.
void request_stop();

/// The signal that asked to stop (SIGINT, SIGTERM or SIGHUP), 0 if none did. The process should
/// exit with 128 + stop_signal() when it is not 0.
int stop_signal();

}  // namespace fem
