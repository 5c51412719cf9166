// Semi-implicit Euler, paper Sec. 3.2.
#include "integrator.h"

#include "workers.h"

#include <cmath>

namespace cps {

Quat rotated(const Quat& o, const Vec3& w, double dt, RotationUpdate rotation) {
  Quat out = o;
  if (rotation == RotationUpdate::linear) {
    // Eq. 3.2.4: o += 1/2 [0, w] o dt, then normalise.
    const Quat spin(0.0, 0.5 * w.x() * dt, 0.5 * w.y() * dt, 0.5 * w.z() * dt);
    out.coeffs() += (spin * o).coeffs();
  } else {
    // Eq. 12.4.1: rotate by the angle |w| dt about w / |w|.
    const double speed = w.norm();
    if (speed > 0.0) {
      const double half = 0.5 * speed * dt;
      const Vec3 axis = w / speed;
      out = Quat(std::cos(half), std::sin(half) * axis.x(), std::sin(half) * axis.y(),
                 std::sin(half) * axis.z()) *
            o;
    }
  }
  out.normalize();
  return out;
}

void integrate(std::vector<Body>& bodies, const Eigen::VectorXd& f_position,
               const Eigen::VectorXd& f_momentum, double dt, RotationUpdate rotation, Workers* workers) {
  // Fewest bodies shared among threads (count): below it waking them costs about what the work does.
  constexpr std::size_t kMinParallel = 256;
  parallel_blocks(workers, bodies.size(), kMinParallel, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      Body& body = bodies[i];
      if (body.is_static()) continue;
      const auto k = 6 * static_cast<Eigen::Index>(i);
      // Momenta that move the body this step (Eqs. 3.2.1, 3.2.2 with the position forces).
      const Vec3 p_next = body.p + f_position.segment<3>(k) * dt;
      const Vec3 l_next = body.l + f_position.segment<3>(k + 3) * dt;
      // Eq. 3.2.3: x += p / m dt.
      body.x += body.inv_mass * p_next * dt;
      body.o = rotated(body.o, body.inv_inertia_world() * l_next, dt, rotation);
      // The stored momenta (Eqs. 3.2.1, 3.2.2).
      body.p += f_momentum.segment<3>(k) * dt;
      body.l += f_momentum.segment<3>(k + 3) * dt;
    }
  });
}

void add_momenta(std::vector<Body>& bodies, const Eigen::VectorXd& f, double dt) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    Body& body = bodies[i];
    if (body.is_static()) continue;
    const auto k = 6 * static_cast<Eigen::Index>(i);
    body.p += f.segment<3>(k) * dt;
    body.l += f.segment<3>(k + 3) * dt;
  }
}

}  // namespace cps
