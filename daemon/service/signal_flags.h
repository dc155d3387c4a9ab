#pragma once
// Signal handling for the daemon, gpsd style: the handlers only set flags and wake the main loop
// through a self-pipe; the loop acts on the flags.

namespace boxd {

// Installs handlers for SIGTERM/SIGINT (terminate) and SIGHUP (reload), and ignores SIGPIPE.
// Returns false if the self-pipe cannot be created.
bool InstallSignalFlags();
// Returns the read end of the self-pipe: readable when a signal arrived or WakeMainLoop() ran.
int SignalWakeFd();
// Drains the self-pipe.
void DrainSignalWakeFd();
// Returns whether a terminate / reload signal arrived since the last call, and clears it.
bool TakeTerminateRequest();
bool TakeReloadRequest();
// Wakes the main loop from another thread (async-signal-safe).
void WakeMainLoop();

}  // namespace boxd
