// Ctrl-C (SIGINT) and SIGTERM for offline renders (README "Stopping a render"). Before the
// render loop, and at any second signal, osr-vk exits at once with 128 + the signal's number
// (130 for Ctrl-C), after removing the temporary file of an output being written
// (image::pendingTempFile), so an existing output is never touched. During the render loop
// the first signal only asks the render to stop: the driver checks stopFlag() between
// submissions, what was rendered is written, and runRender then exits 128 + the signal.
#pragma once
#include <atomic>

namespace osr::app::interrupt {

// Installs the handlers (once per process; later calls do nothing).
void install();
// From now on the first signal sets stopFlag() instead of exiting.
void renderLoopStarts();
// The flag the driver polls; true once a signal arrived during the render loop.
const std::atomic<bool>* stopFlag();
// The signal that asked to stop (SIGINT, SIGTERM), 0 if none.
int stopSignal();

}  // namespace osr::app::interrupt
