#include "app/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <cstring>

#include "image/image_io.h"

namespace osr::app::interrupt {

namespace {

std::atomic<bool> stop{false};
std::atomic<int> stopSig{0};
std::atomic<bool> inRenderLoop{false};
std::atomic<bool> installed{false};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free);

void say(const char* text) {
  ssize_t ignored = ::write(2, text, std::strlen(text));
  (void)ignored;
}

// Only async-signal-safe calls: unlink, write, _exit.
void onSignal(int sig) {
  if (inRenderLoop.load() && !stop.load()) {
    stopSig.store(sig);
    stop.store(true);
    say("\nosr-vk: stopping after the current submission (again to quit at once)\n");
    return;
  }
  if (const char* tmp = image::pendingTempFile()) ::unlink(tmp);
  say("\nosr-vk: interrupted\n");
  ::_exit(128 + sig);
}

}  // namespace

void install() {
  if (installed.exchange(true)) return;
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

void renderLoopStarts() { inRenderLoop.store(true); }

const std::atomic<bool>* stopFlag() { return &stop; }

int stopSignal() { return stopSig.load(); }

}  // namespace osr::app::interrupt
