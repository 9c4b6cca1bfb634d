#include "platform/clock.h"

#include <cstdio>
#include <cstdlib>

namespace slamo::platform {

void SimClock::Advance(double dt_s) {
  // Time never runs backwards: a negative step is a bug in the caller.
  if (!(dt_s >= 0.0)) {
    std::fprintf(stderr, "SimClock::Advance: dt_s must be >= 0, got %g\n", dt_s);
    std::abort();
  }
  now_s_ += dt_s;
}

SteadyClock::SteadyClock() : origin_(std::chrono::steady_clock::now()) {}

double SteadyClock::NowS() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - origin_).count();
}

}  // namespace slamo::platform
