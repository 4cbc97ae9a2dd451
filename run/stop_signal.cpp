#include "run/stop_signal.h"

#include <csignal>

namespace morphoflow {

namespace {

volatile std::sig_atomic_t g_received = 0;
struct sigaction g_previous[2];

extern "C" void onStop(int sig) { g_received = sig; }

}  // namespace

StopSignals::StopSignals() {
  g_received = 0;  // a new run (the Python module runs several in one process)
  struct sigaction sa {};
  sa.sa_handler = onStop;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a wait on ffmpeg wakes up
  sigaction(SIGINT, &sa, &g_previous[0]);
  sigaction(SIGTERM, &sa, &g_previous[1]);
}

StopSignals::~StopSignals() {
  sigaction(SIGINT, &g_previous[0], nullptr);
  sigaction(SIGTERM, &g_previous[1], nullptr);
}

int StopSignals::received() { return g_received; }

}  // namespace morphoflow
