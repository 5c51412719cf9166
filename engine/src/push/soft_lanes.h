// The soft step's sweeps in SIMD lanes: a graph colour's manifolds four at a time, one per lane
// (Box3D's wide contact solver, erincatto/box3d 0.1.0 src/contact_solver.c: b3GatherBodies,
// b3ScatterBodies, b3WarmStartContacts_Convex, b3SolveContacts_Convex with useBias true and
// false; Box2D v3's src/contact_solver.c, which it follows). A colour's manifolds share no moving
// body, so the lanes' bodies are gathered, swept and scattered back independently.
//
// Each lane does, operation for operation, what soft_step.cpp's scalar sweep does for its
// manifold, in double, in Eigen's order of the scalar code's sums (a 3-vector's dot product as
// (x0 + x1) + x2; a 3 x 3 matrix times a vector with rows 0 and 1 as (m0 v0 + m1 v1) + m2 v2 and
// row 2 as m0 v0 + (m1 v1 + m2 v2), the order Eigen 3.4 evaluates them in on x86-64), without
// fused multiply-adds, so the lanes give the scalar sweep's state bit for bit. The kernels are
// built twice on x86-64 with GCC (target_clones: AVX2 and the SSE2 baseline), the loader chooses
// by the CPU, and both give the same bits. Differences from Box3D: four doubles a lane group
// where Box3D has four floats (SSE2 or NEON); the points' I^-1 (r x n) formed in the sweep.

#ifndef CPS_ENGINE_PUSH_SOFT_LANES_H
#define CPS_ENGINE_PUSH_SOFT_LANES_H

#include "../buffers.h"
#include "cps/math.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define CPS_LANES_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CPS_LANES_CLONES
#endif

namespace cps::soft {

/// Four doubles, one per lane (GCC's and Clang's vector extension; split into two SSE2 registers
/// where AVX is not enabled). Aligned to 32 bytes in every build, as the AVX2 kernels load them
/// (without AVX, GCC would align the type to 16).
using Lanes = double __attribute__((vector_size(4 * sizeof(double)), aligned(32)));
/// A lane mask: all bits set (true) or clear, per lane, as the vector comparisons give it.
using LaneMask = std::int64_t __attribute__((vector_size(4 * sizeof(std::int64_t)), aligned(32)));
inline constexpr int kLanes = 4;

/// A body's state in the soft step's solver (soft_step.cpp; after the n bodies, zero stand-ins
/// for the static bodies and the world). Four whole cache lines, ordered by what the sweeps read:
/// the warm start the first two (v, w, I^-1, 1/m), the solve and relax also the third and the
/// fourth (dp, dR), the integration dq.
struct alignas(64) SolverBody {
  Vec3 v = Vec3::Zero();       // m/s
  Vec3 w = Vec3::Zero();       // rad/s
  Mat3 inv_I = Mat3::Zero();   // 1/(kg m^2), world frame, start of the step
  double inv_mass = 0.0;       // 1/kg
  Vec3 dp = Vec3::Zero();      // m: displacement since the start of the step
  Mat3 dR = Mat3::Identity();  // dq as a matrix, once a substep
  Quat dq = Quat::Identity();  // rotation since the start of the step
};
static_assert(sizeof(SolverBody) == 256, "a solver body fills four cache lines");
static_assert(offsetof(SolverBody, dp) == 128, "what the warm start reads fills the first two lines");

/// Box3D's soft coefficients of one kind of row over a substep (b3MakeSoft; soft_step.cpp).
struct Softness {
  double bias_rate = 0.0;      // 1/s
  double mass_scale = 1.0;     // dimensionless
  double impulse_scale = 0.0;  // dimensionless
};

/// A 3-vector per lane (x, y, z: 4 lanes each).
struct LaneVec3 {
  Lanes x{};
  Lanes y{};
  Lanes z{};
};

/// Point k of each lane's manifold (zero in a lane whose manifold has fewer points): the scalar
/// sweep's ContactPoint and its normal row, in lanes, in the order a sweep reads them. Units as
/// there: r_a and r_b m, mass kg, impulse N s, separation and lever arm m. Its row's axis is
/// its manifold's normal (every point of a Manifold has the same), read from the group
/// (lanes::axis_of); its I^-1 (r x axis) are formed in the sweep from the bodies' I^-1, as
/// prepare formed them: so a point streams 80 bytes a lane instead of 168. Its step's total
/// impulse is kept apart (LaneSweep::totals), summed only where a contact has a restitution
/// target.
struct LanePoint {
  LaneVec3 r_a;
  LaneVec3 r_b;
  Lanes base_separation{};
  Lanes mass{};
  Lanes impulse{};
  Lanes lever_arm{};
};
static_assert(sizeof(LanePoint) == 10 * sizeof(Lanes), "a point streams 80 bytes a lane");

/// A point's total normal impulse over the step (N s), per lane (a struct, so that containers
/// keep the lanes' alignment).
struct LaneTotal {
  Lanes impulse{};
};

/// Up to kLanes manifolds of one colour, their friction at the centre in lanes (the scalar
/// sweep's ManifoldFriction) and their points from `first_point` in the group's point array.
struct LaneGroup {
  int a[kLanes] = {-1, -1, -1, -1};  // moving body index, or -1 (static, the world, no manifold)
  int b[kLanes] = {-1, -1, -1, -1};
  int slot[kLanes] = {-1, -1, -1, -1};  // the manifold's slot (its place in colour order), or -1
  std::size_t first_point = 0;
  int points = 0;  // the most points of a lane's manifold
  LaneVec3 normal;
  LaneVec3 t1;
  LaneVec3 t2;
  LaneVec3 center_a;  // m
  LaneVec3 center_b;
  Lanes k00{};  // kg: the 2 x 2 tangent mass, row by row
  Lanes k01{};
  Lanes k10{};
  Lanes k11{};
  Lanes impulse1{};  // N s along t1
  Lanes impulse2{};  // N s along t2
  Lanes twist_mass{};     // kg m^2
  Lanes twist_impulse{};  // N m s
  Lanes mu{};
  Lanes fixed_limit{};  // N s a substep per point; < 0: the coupled model
  Lanes count{};        // the lane's points
  Lanes touches_static{};  // 1 where the manifold has a static body, else 0
};

/// What a sweep of lanes reads besides the groups (soft_step.cpp's members of the same names).
struct LaneSweep {
  SolverBody* bodies = nullptr;   // the solver bodies, indexed by LaneGroup::a and b
  SolverBody* stand_in = nullptr;  // a zero body for index -1 (read, never written)
  LanePoint* points = nullptr;
  bool prefetch = false;           // the sweeps prefetch (from detail::kPrefetchFrom bytes of points)
  LaneTotal* totals = nullptr;     // per point of `points`: the step's sum of its impulses, or null
  bool friction = false;           // the manifolds have friction rows
  double inv_h = 0.0;              // 1/s
  Softness contact;
  Softness stiff;                  // contacts with a static body
  double slop = 0.0;               // m
  double max_push = 0.0;           // m/s
};

namespace lanes {

[[gnu::always_inline]] inline Lanes splat(double x) { return Lanes{x, x, x, x}; }

[[gnu::always_inline]] inline Lanes select(LaneMask m, Lanes a, Lanes b) { return m ? a : b; }

[[gnu::always_inline]] inline LaneVec3 operator+(const LaneVec3& a, const LaneVec3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
[[gnu::always_inline]] inline LaneVec3 operator-(const LaneVec3& a, const LaneVec3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
[[gnu::always_inline]] inline LaneVec3 operator*(Lanes s, const LaneVec3& a) { return {s * a.x, s * a.y, s * a.z}; }

// Eigen's order for Vec3::dot: (x0 + x1) + x2.
[[gnu::always_inline]] inline Lanes dot(const LaneVec3& a, const LaneVec3& b) {
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}

[[gnu::always_inline]] inline LaneVec3 cross(const LaneVec3& a, const LaneVec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

/// A 3 x 3 matrix per lane, m[row][column].
struct LaneMat3 {
  Lanes m[3][3];
};

// Eigen 3.4's order for Mat3 * Vec3 on x86-64: rows 0 and 1 in a packet, row 2 as a reduction.
[[gnu::always_inline]] inline LaneVec3 mul(const LaneMat3& M, const LaneVec3& v) {
  return {(M.m[0][0] * v.x + M.m[0][1] * v.y) + M.m[0][2] * v.z,
          (M.m[1][0] * v.x + M.m[1][1] * v.y) + M.m[1][2] * v.z,
          M.m[2][0] * v.x + (M.m[2][1] * v.y + M.m[2][2] * v.z)};
}

// The lanes' bodies on one side of their rows.
struct LaneBody {
  LaneVec3 v;
  LaneVec3 w;
  LaneVec3 dp;
  LaneMat3 dR{};
  LaneMat3 inv_I{};
  Lanes inv_mass{};
  SolverBody* body[kLanes];
  bool moving[kLanes];
};

// A SolverBody read as 32 doubles: four of them at a time (one 32-byte quarter of a cache line)
// are one load. The fields' places, in doubles (Eigen stores a Mat3 column by column):
// v 0-2, w 3-5, inv_I 6-14, inv_mass 15, dp 16-18, dR 19-27.
static_assert(offsetof(SolverBody, v) == 0 && offsetof(SolverBody, w) == 3 * sizeof(double) &&
                  offsetof(SolverBody, inv_I) == 6 * sizeof(double) &&
                  offsetof(SolverBody, inv_mass) == 15 * sizeof(double) &&
                  offsetof(SolverBody, dR) == 19 * sizeof(double),
              "gather() and scatter() read the solver body in this order");

// Four doubles from p (32-byte aligned).
[[gnu::always_inline]] inline Lanes load4(const double* p) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// The 4 x 4 transpose: lane l of c[k] is lane k of r[l] (two rounds of shuffles, no arithmetic).
[[gnu::always_inline]] inline void transpose(const Lanes (&r)[kLanes], Lanes (&c)[kLanes]) {
  const Lanes t0 = __builtin_shufflevector(r[0], r[1], 0, 4, 2, 6);
  const Lanes t1 = __builtin_shufflevector(r[0], r[1], 1, 5, 3, 7);
  const Lanes t2 = __builtin_shufflevector(r[2], r[3], 0, 4, 2, 6);
  const Lanes t3 = __builtin_shufflevector(r[2], r[3], 1, 5, 3, 7);
  c[0] = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
  c[1] = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
  c[2] = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
  c[3] = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
}

// Doubles 4 k to 4 k + 3 of the four bodies, one field a Lanes (c[i]: double 4 k + i).
[[gnu::always_inline]] inline void gather_quarter(const SolverBody* const* body, int k, Lanes (&c)[kLanes]) {
  Lanes r[kLanes];
  for (int l = 0; l < kLanes; ++l) r[l] = load4(reinterpret_cast<const double*>(body[l]) + 4 * k);
  transpose(r, c);
}

// The lanes' bodies of `index` (kLanes body indices, -1 for the stand-in); their positions (dp,
// dR) only when asked for. A quarter of each body's line at a time, transposed (as Box3D's
// b3GatherBodies): the same numbers as reading them one by one.
[[gnu::always_inline]] inline void gather(LaneBody& L, const int* index, const LaneSweep& s, bool positions) {
  for (int l = 0; l < kLanes; ++l) {
    L.moving[l] = index[l] >= 0;
    L.body[l] = L.moving[l] ? s.bodies + index[l] : s.stand_in;
  }
  Lanes c[kLanes];
  gather_quarter(L.body, 0, c);  // v, w.x
  L.v = {c[0], c[1], c[2]};
  L.w.x = c[3];
  gather_quarter(L.body, 1, c);  // w.y, w.z, I^-1 (0, 0), (1, 0)
  L.w.y = c[0];
  L.w.z = c[1];
  L.inv_I.m[0][0] = c[2];
  L.inv_I.m[1][0] = c[3];
  gather_quarter(L.body, 2, c);  // I^-1 (2, 0), (0, 1), (1, 1), (2, 1)
  L.inv_I.m[2][0] = c[0];
  L.inv_I.m[0][1] = c[1];
  L.inv_I.m[1][1] = c[2];
  L.inv_I.m[2][1] = c[3];
  gather_quarter(L.body, 3, c);  // I^-1 (0, 2), (1, 2), (2, 2), 1/m
  L.inv_I.m[0][2] = c[0];
  L.inv_I.m[1][2] = c[1];
  L.inv_I.m[2][2] = c[2];
  L.inv_mass = c[3];
  if (!positions) return;
  gather_quarter(L.body, 4, c);  // dp, dR (0, 0)
  L.dp = {c[0], c[1], c[2]};
  L.dR.m[0][0] = c[3];
  gather_quarter(L.body, 5, c);  // dR (1, 0), (2, 0), (0, 1), (1, 1)
  L.dR.m[1][0] = c[0];
  L.dR.m[2][0] = c[1];
  L.dR.m[0][1] = c[2];
  L.dR.m[1][1] = c[3];
  gather_quarter(L.body, 6, c);  // dR (2, 1), (0, 2), (1, 2), (2, 2)
  L.dR.m[2][1] = c[0];
  L.dR.m[0][2] = c[1];
  L.dR.m[1][2] = c[2];
  L.dR.m[2][2] = c[3];
}

// Writes the lanes' velocities back to their moving bodies (a stand-in's stay zero: it has no
// mass and no inverse inertia), transposed back: the first quarter of a body's line whole (v,
// w.x), then w.y and w.z.
[[gnu::always_inline]] inline void scatter(const LaneBody& L) {
  using Pair = double __attribute__((vector_size(2 * sizeof(double))));
  Lanes r[kLanes];
  transpose({L.v.x, L.v.y, L.v.z, L.w.x}, r);
  const Lanes even = __builtin_shufflevector(L.w.y, L.w.z, 0, 4, 2, 6);  // lanes 0 and 2
  const Lanes odd = __builtin_shufflevector(L.w.y, L.w.z, 1, 5, 3, 7);   // lanes 1 and 3
  const Pair yz[kLanes] = {__builtin_shufflevector(even, even, 0, 1), __builtin_shufflevector(odd, odd, 0, 1),
                           __builtin_shufflevector(even, even, 2, 3), __builtin_shufflevector(odd, odd, 2, 3)};
  for (int l = 0; l < kLanes; ++l) {
    if (!L.moving[l]) continue;
    auto* p = reinterpret_cast<double*>(L.body[l]);
    std::memcpy(p, &r[l], sizeof r[l]);
    std::memcpy(p + 4, &yz[l], sizeof yz[l]);
  }
}

// A point's normal row as set_axis_row (soft_step.cpp) forms it: r x axis on each side and
// I^-1 (r x axis).
struct LaneRow {
  LaneVec3 rn_a;
  LaneVec3 rn_b;
  LaneVec3 Irn_a;
  LaneVec3 Irn_b;
};

[[gnu::always_inline]] inline LaneRow row_of(const LanePoint& q, const LaneVec3& axis, const LaneBody& A,
                                              const LaneBody& B) {
  LaneRow row;
  row.rn_a = cross(q.r_a, axis);
  row.rn_b = cross(q.r_b, axis);
  row.Irn_a = mul(A.inv_I, row.rn_a);
  row.Irn_b = mul(B.inv_I, row.rn_b);
  return row;
}

// Point k's axis in each lane: its manifold's normal, or zero in a lane whose manifold has no
// point k (as a zero point's row: its impulse stays +0 and adds exactly nothing to the bodies).
[[gnu::always_inline]] inline LaneVec3 axis_of(const LaneGroup& g, int k) {
  const LaneMask has = splat(static_cast<double>(k)) < g.count;
  return {select(has, g.normal.x, splat(0.0)), select(has, g.normal.y, splat(0.0)),
          select(has, g.normal.z, splat(0.0))};
}

// soft_step.cpp's apply(): impulse P along a point's normal row (its axis), -P to a, +P to b.
[[gnu::always_inline]] inline void apply(const LaneVec3& axis, const LaneRow& row, Lanes P, LaneBody& A, LaneBody& B) {
  A.v = A.v - (A.inv_mass * P) * axis;
  A.w = A.w - P * row.Irn_a;
  B.v = B.v + (B.inv_mass * P) * axis;
  B.w = B.w + P * row.Irn_b;
}

// soft_step.cpp's apply_friction(): impulse P (world frame) at the manifold's centre.
[[gnu::always_inline]] inline void apply_friction(const LaneGroup& g, const LaneVec3& P, LaneBody& A, LaneBody& B) {
  A.v = A.v - A.inv_mass * P;
  A.w = A.w - mul(A.inv_I, cross(g.center_a, P));
  B.v = B.v + B.inv_mass * P;
  B.w = B.w + mul(B.inv_I, cross(g.center_b, P));
}

// soft_step.cpp's apply_twist(): twist impulse L about the normal.
[[gnu::always_inline]] inline void apply_twist(const LaneGroup& g, Lanes L, LaneBody& A, LaneBody& B) {
  const LaneVec3 torque = L * g.normal;
  A.w = A.w - mul(A.inv_I, torque);
  B.w = B.w + mul(B.inv_I, torque);
}

[[gnu::always_inline]] inline void warm_start_group(const LaneGroup& g, const LaneSweep& s) {
  LaneBody A;
  LaneBody B;
  gather(A, g.a, s, false);
  gather(B, g.b, s, false);
  const LanePoint* q = s.points + g.first_point;
  for (int k = 0; k < g.points; ++k) {
    const LaneVec3 axis = axis_of(g, k);
    apply(axis, row_of(q[k], axis, A, B), q[k].impulse, A, B);
  }
  if (s.friction) {
    apply_friction(g, g.impulse1 * g.t1 + g.impulse2 * g.t2, A, B);
    apply_twist(g, g.twist_impulse, A, B);
  }
  scatter(A);
  scatter(B);
}

// soft_step.cpp's solve_normal() for point q of each lane, along `axis` (axis_of); `stiff` marks
// the lanes whose manifold has a static body; `total` the point's sum over the step, or null.
template <bool kBias>
[[gnu::always_inline]] inline Lanes solve_normal(LanePoint& q, const LaneVec3& axis, LaneMask stiff, LaneTotal* total,
                                                 LaneBody& A, LaneBody& B, const LaneSweep& s) {
  const LaneVec3 ds = (B.dp - A.dp) + (mul(B.dR, q.r_b) - mul(A.dR, q.r_a));
  const Lanes sep = dot(axis, ds) + q.base_separation;
  const LaneMask speculative = sep > 0.0;
  Lanes bias = select(speculative, sep * s.inv_h, splat(0.0));
  Lanes mass_scale = splat(1.0);
  Lanes impulse_scale = splat(0.0);
  if constexpr (kBias) {
    const Lanes k_mass = select(stiff, splat(s.stiff.mass_scale), splat(s.contact.mass_scale));
    const Lanes k_rate = select(stiff, splat(s.stiff.bias_rate), splat(s.contact.bias_rate));
    const Lanes k_impulse = select(stiff, splat(s.stiff.impulse_scale), splat(s.contact.impulse_scale));
    const Lanes shifted = sep + s.slop;
    const Lanes closing = select(0.0 < shifted, splat(0.0), shifted);  // std::min(s + slop, 0)
    const Lanes push = (k_mass * k_rate) * closing;
    const Lanes soft = select(push < -s.max_push, splat(-s.max_push), push);  // std::max(push, -max)
    bias = select(speculative, bias, soft);
    mass_scale = select(speculative, mass_scale, k_mass);
    impulse_scale = select(speculative, impulse_scale, k_impulse);
  }
  const LaneRow row = row_of(q, axis, A, B);
  const Lanes speed = (dot(axis, B.v - A.v) + dot(row.rn_b, B.w)) - dot(row.rn_a, A.w);
  const Lanes old = q.impulse;
  Lanes next = old - q.mass * (mass_scale * speed + bias) - impulse_scale * old;
  next = select(next < 0.0, splat(0.0), next);  // std::max(next, 0)
  q.impulse = next;
  if (total != nullptr) total->impulse = total->impulse + next;
  apply(axis, row, next - old, A, B);
  return next;
}

// soft_step.cpp's solve_friction(): the twist, then the two tangent rows at the centre.
[[gnu::always_inline]] inline void solve_friction(LaneGroup& g, Lanes total, Lanes twist_limit, LaneBody& A,
                                                  LaneBody& B) {
  Lanes limit = g.mu * total;
  Lanes twist_max = g.mu * twist_limit;
  const LaneMask fixed = g.fixed_limit >= 0.0;
  const Lanes fixed_limit = g.fixed_limit * g.count;
  // Every lane computes both sides of a choice: a denominator of 0 becomes 1 where its side is
  // not taken, so that no lane divides by zero (the tests trap it).
  const LaneMask pressed = total > 0.0;
  const Lanes fixed_twist = select(pressed, fixed_limit * twist_limit / select(pressed, total, splat(1.0)), splat(0.0));
  limit = select(fixed, fixed_limit, limit);
  twist_max = select(fixed, fixed_twist, twist_max);
  {
    const Lanes speed = dot(g.normal, B.w - A.w);
    const Lanes old = g.twist_impulse;
    const Lanes raw = old - g.twist_mass * speed;
    const Lanes low = -twist_max;
    Lanes next = select(raw < low, low, select(twist_max < raw, twist_max, raw));  // std::clamp
    g.twist_impulse = next;
    apply_twist(g, next - old, A, B);
  }
  const LaneVec3 vr = (B.v + cross(B.w, g.center_b)) - (A.v + cross(A.w, g.center_a));
  const Lanes vt1 = dot(vr, g.t1);
  const Lanes vt2 = dot(vr, g.t2);
  Lanes next1 = g.impulse1 - (g.k00 * vt1 + g.k01 * vt2);
  Lanes next2 = g.impulse2 - (g.k10 * vt1 + g.k11 * vt2);
  const Lanes length2 = next1 * next1 + next2 * next2;
  const LaneMask outside = length2 > limit * limit;
  const Lanes root{std::sqrt(length2[0]), std::sqrt(length2[1]), std::sqrt(length2[2]), std::sqrt(length2[3])};
  const Lanes scale = limit / select(outside, root, splat(1.0));  // root > 0 where outside
  next1 = select(outside, next1 * scale, next1);
  next2 = select(outside, next2 * scale, next2);
  const Lanes d1 = next1 - g.impulse1;
  const Lanes d2 = next2 - g.impulse2;
  g.impulse1 = next1;
  g.impulse2 = next2;
  apply_friction(g, d1 * g.t1 + d2 * g.t2, A, B);
}

template <bool kBias>
[[gnu::always_inline]] inline void solve_group(LaneGroup& g, const LaneSweep& s) {
  const bool friction = !kBias && s.friction;
  LaneBody A;
  LaneBody B;
  gather(A, g.a, s, true);
  gather(B, g.b, s, true);
  LanePoint* q = s.points + g.first_point;
  LaneTotal* totals = s.totals != nullptr ? s.totals + g.first_point : nullptr;
  const LaneMask stiff = g.touches_static != 0.0;
  Lanes total = splat(0.0);
  Lanes twist_limit = splat(0.0);
  for (int k = 0; k < g.points; ++k) {
    const Lanes next = solve_normal<kBias>(q[k], axis_of(g, k), stiff, totals != nullptr ? totals + k : nullptr, A, B, s);
    total = total + next;
    twist_limit = twist_limit + q[k].lever_arm * next;
  }
  if (friction) solve_friction(g, total, twist_limit, A, B);
  scatter(A);
  scatter(B);
}

inline constexpr std::size_t kPrefetchAhead = 2;  // groups

// The bytes at the start of a SolverBody that the warm start reads (v, w, I^-1, 1/m).
inline constexpr std::size_t kWarmStartBodyBytes = offsetof(SolverBody, dp);

// Asks for the cache lines of group i + kPrefetchAhead of [groups, groups + count) ahead of its
// sweep, where s.prefetch: the first body_bytes of each of its bodies, and the group and its
// points. The groups and points are streamed in order, but the hardware's own prefetching fell
// behind them (docs/benchmarks.md).
[[gnu::always_inline]] inline void prefetch(const LaneGroup* groups, std::size_t i, std::size_t count,
                                            const LaneSweep& s, std::size_t body_bytes = sizeof(SolverBody)) {
  if (!s.prefetch || i + kPrefetchAhead >= count) return;
  const LaneGroup& g = groups[i + kPrefetchAhead];
  for (int l = 0; l < kLanes; ++l) {
    if (g.a[l] >= 0) detail::prefetch_lines<true>(s.bodies + g.a[l], body_bytes);
    if (g.b[l] >= 0) detail::prefetch_lines<true>(s.bodies + g.b[l], body_bytes);
  }
  detail::prefetch_lines<true>(&g, sizeof(LaneGroup));
  detail::prefetch_lines<true>(s.points + g.first_point, static_cast<std::size_t>(g.points) * sizeof(LanePoint));
}

}  // namespace lanes

/// The warm start of groups [groups, groups + count): every point's accumulated normal impulse
/// and each manifold's friction and twist applied to the bodies (soft_step.cpp's warm_start()).
CPS_LANES_CLONES inline void warm_start_lanes(const LaneGroup* groups, std::size_t count, const LaneSweep& s) {
  for (std::size_t i = 0; i < count; ++i) {
    lanes::prefetch(groups, i, count, s, lanes::kWarmStartBodyBytes);
    lanes::warm_start_group(groups[i], s);
  }
}

/// One sweep of the solve (use_bias) or the relax over groups [groups, groups + count)
/// (soft_step.cpp's solve()).
CPS_LANES_CLONES inline void solve_lanes(LaneGroup* groups, std::size_t count, const LaneSweep& s, bool use_bias) {
  if (use_bias) {
    for (std::size_t i = 0; i < count; ++i) {
      lanes::prefetch(groups, i, count, s);
      lanes::solve_group<true>(groups[i], s);
    }
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      lanes::prefetch(groups, i, count, s);
      lanes::solve_group<false>(groups[i], s);
    }
  }
}

}  // namespace cps::soft

#endif  // CPS_ENGINE_PUSH_SOFT_LANES_H
