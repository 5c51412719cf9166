#pragma once
// Semi-implicit Euler integration (paper Sec. 3.2, Eqs. 3.2.1-3.2.4).

#include "cps/body.h"
#include "cps/parameters.h"

#include <Eigen/Core>

#include <vector>

namespace cps {

class Workers;  // workers.h

/// The orientation o (unit quaternion) turned by angular velocity w (rad/s, world frame) over dt
/// (s): o + 1/2 [0, w] o dt (Eq. 3.2.4) or the axis-angle step of Eq. 12.4.1, then normalised.
/// No errors.
Quat rotated(const Quat& o, const Vec3& w, double dt, RotationUpdate rotation);

/// Advances every movable body by dt (s, > 0).
/// f_position and f_momentum (6n each): force and torque per body (N, N m), external plus
/// constraint forces. Momenta advanced with f_position move the bodies (Eqs. 3.2.3, 3.2.4):
///   x += (p + f dt) / m dt;  o += 1/2 [0, I^-1 (l + tau dt)] o dt, then o is normalised
///   (or the exact axis-angle step of Eq. 12.4.1 with RotationUpdate::exact);
/// the stored momenta are advanced with f_momentum (Eqs. 3.2.1, 3.2.2). For the ordinary step
/// both are the same vector; the single frame push factor (Sec. 8.1) passes f_cv and f_c0.
/// I^-1 is taken at the orientation before the step. Static bodies do not move. With `workers`
/// (null: the calling thread alone), the bodies are shared among its threads: each body's numbers
/// are the same for every thread count.
void integrate(std::vector<Body>& bodies, const Eigen::VectorXd& f_position,
               const Eigen::VectorXd& f_momentum, double dt,
               RotationUpdate rotation = RotationUpdate::linear, Workers* workers = nullptr);

/// Advances every movable body's momenta by f dt (p += force dt, l += torque dt; f: 6n, N and
/// N m; dt in s) without moving it: the relax of temporal Gauss-Seidel (push/tgs.cpp) sets the
/// velocity after its substeps' positions have moved.
void add_momenta(std::vector<Body>& bodies, const Eigen::VectorXd& f, double dt);

}  // namespace cps
