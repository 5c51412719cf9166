#pragma once
// An independent reference for the pendulum wave: one pendulum in reduced coordinates.
//
// A massless rod of length l is pinned at a fixed pivot and at a point on the surface of a ball
// of radius r and mass m; the ball turns freely about that pin. In the plane of the swing the
// state is the rod angle theta and the angle phi of the line from the pin to the ball centre,
// both from the downward vertical. With k = I / m = 2/5 r^2 (solid ball) the Lagrangian
//   L = m/2 (l^2 th'^2 + r^2 ph'^2 + 2 l r th' ph' cos(th - ph)) + m k / 2 ph'^2
//       + m g (l cos th + r cos ph)
// gives the equations of motion
//   [ l^2          l r cos(d) ] [th'']   [ -l r ph'^2 sin(d) - g l sin th ]
//   [ l r cos(d)   r^2 + k    ] [ph''] = [  l r th'^2 sin(d) - g r sin ph ],   d = th - ph.
// Linearised about rest, det(K - w^2 M) = 0 gives
//   l k w^4 - g (r^2 + k + r l) w^2 + g^2 r = 0,
// whose smaller root is the slow (pendulum) mode; the larger one is the ball wobbling on its pin.

#include <utility>

namespace cps::scenes {

/// Parameters of one pendulum: rod length l (m, > 0), ball radius r (m, > 0), gravity g
/// (m/s^2, > 0).
struct PinnedBallPendulum {
  double rod_length = 1.0;
  double radius = 0.02;
  double gravity = 10.0;
};

/// State: rod angle theta and pin-to-centre angle phi (rad, from the downward vertical) and
/// their rates (rad/s).
struct PendulumState {
  double theta = 0.0;
  double phi = 0.0;
  double theta_rate = 0.0;
  double phi_rate = 0.0;
};

/// Angular frequency (rad/s) of the slow small-oscillation mode (see the header comment).
double slow_mode_frequency(const PinnedBallPendulum& p);

/// The rod length (m) whose slow-mode period is `period` (s, > 0) for a ball of radius r (m)
/// under gravity g (m/s^2), by bisection to 1e-13 m. Throws std::invalid_argument if no length
/// in (0, 1000] m gives that period.
double rod_length_for_period(double period, double radius, double gravity);

/// Integrates the equations of motion from `start` for `seconds` (s, >= 0) with classical RK4
/// at a step of at most `step` (s, > 0; the last step is shortened to land on `seconds`).
PendulumState integrate_rk4(const PinnedBallPendulum& p, PendulumState start, double seconds,
                            double step);

/// Angle (rad) of the ball centre seen from the pivot, from the downward vertical:
/// atan2(l sin th + r sin ph, l cos th + r cos ph).
double centre_angle(const PinnedBallPendulum& p, const PendulumState& s);

/// The centre angle (rad, as centre_angle) and its rate (rad/s).
std::pair<double, double> centre_angle_and_rate(const PinnedBallPendulum& p,
                                                const PendulumState& s);

/// The phase (rad, in [-pi, pi]) of a swing at `angle` (rad) and `rate` (rad/s): its angle in
/// the plane (angle, -rate / w), w the slow mode's small-oscillation frequency (rad/s, > 0).
double swing_phase(double angle, double rate, double w);

/// RK4 step (s) of the pendulum wave's reference (Sec. 10.3's scene, pendulum_wave.cpp). RK4's
/// error falls as step^4: over the scene's 62 s the phase of its shortest rod stays within
/// 2e-6 deg of that at a fifth of this step (a test checks both), far below the phase errors
/// the scene measures (tenths of a degree and more).
inline constexpr double kPendulumWaveReferenceStep = 5e-4;

}  // namespace cps::scenes
