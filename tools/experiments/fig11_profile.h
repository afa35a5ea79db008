// The paper's Fig. 11 experiment (§VI-B), as pure maths: no I/O, no clock.
//
// A SETSPEED(v, ω) profile for a differential-drive base, one frame every
// `frame_period`, that traces four small half circles of radius r (turning
// left, right, left, right) and then one large half circle of radius 4r that
// brings the robot back to its start (docs/experiment.md has the drawing):
//
//   start (0, 0, θ=0) ─ left  r  → (0, 2r, π)
//                     ─ right r  → (0, 4r, 0)
//                     ─ left  r  → (0, 6r, π)
//                     ─ right r  → (0, 8r, 0)
//                     ─ right 4r → (0, 0, −π)   (back at the start)
//
// (coordinates in the start pose's frame). The speed v is constant; each small
// half circle lasts n frames and the large one 4n, so every half circle ends
// exactly on a frame boundary and the path closes exactly. The last frame,
// at offset 8n·frame_period, is SETSPEED(0, 0).
//
// The ideal path is the exact integration of the profile (a unicycle holding
// each frame's (v, ω) for one frame period) from the start pose: one circular
// arc per frame.
#pragma once

#include <cstddef>
#include <vector>

namespace robotalk::experiments {

struct Pose2 {
  double x = 0, y = 0, theta = 0;
};

struct Fig11Params {
  /// Total path length (m): 4 small half circles (4πr) + the large one (4πr) = 8πr.
  double length = 6.0;
  /// Requested duration (s); rounded to a multiple of 8·frame_period.
  double duration = 30.0;
  double frame_period = 0.1;
};

/// One frame: hold (v, ω) from `offset` for one frame period.
struct SpeedFrame {
  double offset = 0;  ///< s from the sequence start
  double v = 0;       ///< m/s
  double omega = 0;   ///< rad/s
};

struct Fig11Profile {
  Fig11Params params;
  int frames_per_small = 0;        ///< n: frames of one small half circle
  double radius = 0;               ///< r (m)
  double speed = 0;                ///< v (m/s)
  double duration = 0;             ///< 8 n frame_period (s): when the final stop frame plays
  std::vector<SpeedFrame> frames;  ///< 8n moving frames, then the stop frame
};

/// Builds the profile. Throws std::invalid_argument for non-positive or
/// non-finite parameters.
Fig11Profile MakeFig11Profile(const Fig11Params& params);

/// A circular arc (or a straight segment when omega == 0) driven for `dt` from `start`.
struct Arc {
  Pose2 start;
  double v = 0, omega = 0, dt = 0;
  Pose2 At(double t) const;  ///< pose after t ∈ [0, dt]
  Pose2 End() const { return At(dt); }
  /// Euclidean distance from (x, y) to the arc (exact).
  double Distance(double x, double y) const;
};

/// The ideal path: one arc per moving frame, integrated exactly from `start`.
class IdealPath {
 public:
  IdealPath(const Fig11Profile& profile, const Pose2& start);
  const std::vector<Arc>& arcs() const { return arcs_; }
  Pose2 End() const;
  /// Distance from (x, y) to the nearest point of the whole path.
  double Distance(double x, double y) const;
  /// Pose at time t after the start (clamped to [0, duration]).
  Pose2 At(double t) const;

 private:
  std::vector<Arc> arcs_;
  Pose2 start_;
};

/// Summary of deviations of a set of points from the ideal path.
struct Deviation {
  double mean = 0, max = 0;
  std::size_t samples = 0;
};
Deviation MeasureDeviation(const IdealPath& path, const std::vector<Pose2>& samples);

double WrapAngle(double a);

}  // namespace robotalk::experiments
