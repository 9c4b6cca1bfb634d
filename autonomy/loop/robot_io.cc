#include "autonomy/loop/robot_io.h"

namespace slamo::autonomy {

platform::DriveBodyLink DriveLinkFor(RobotIo& io, const field::RobotConfig& robot) {
  platform::DriveBodyLink body;
  body.base = &io.drive();
  body.metres_per_tick =
      platform::kPi * robot.drive.wheel_diameter_m / robot.drive.encoder_ticks_per_rev;
  body.track_width_m = robot.drive.track_width_m;
  body.odometry_start = io.OdometryPose();
  body.clock = &io.clock();
  body.advance = [&io](double dt_s) { io.Advance(dt_s); };
  if (io.TruePose()) body.truth = [&io]() { return *io.TruePose(); };
  return body;
}

}  // namespace slamo::autonomy
