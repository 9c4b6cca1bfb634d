// Where components get the time. Everything takes a Clock it is given; only SteadyClock reads
// the machine's clock, so a dry run on SimClock can go faster than real time and replay
// exactly.
#pragma once

#include <chrono>

namespace slamo::platform {

class Clock {
 public:
  virtual ~Clock() = default;
  // Seconds since the clock's own origin.
  virtual double NowS() const = 0;
};

// Simulated time: stands still until its owner calls Advance().
class SimClock : public Clock {
 public:
  explicit SimClock(double start_s = 0.0) : now_s_(start_s) {}

  double NowS() const override { return now_s_; }
  // Moves time forward by dt_s (>= 0; a negative step aborts).
  void Advance(double dt_s);

 private:
  double now_s_;
};

// Real monotonic time, in seconds since construction.
class SteadyClock : public Clock {
 public:
  SteadyClock();
  double NowS() const override;

 private:
  std::chrono::steady_clock::time_point origin_;
};

}  // namespace slamo::platform
