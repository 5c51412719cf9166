#pragma once
// The world's parameters: the methods to choose from, WorldDef (one value of each), and the
// parameter table that defines each parameter once: its name, command-line flag, JSON key (with
// its unit as a suffix), unit, allowed range or names, and help. Validation, the command-line
// options, run.json, `cps simulate --json` and the report all read the table, so a new world
// parameter is one WorldDef member plus one table entry (engine/src/parameters.cpp) plus its
// physics.

#include "cps/math.h"

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace cps {

class PushMethod;  // internal to the engine: engine/src/push/push_method.h
struct WorldDef;

/// How violated constraints are corrected; each is one file in engine/src/push/, made through
/// its entry in the push parameter's table (PushTraits).
enum class PushMode {
  baumgarte,  ///< the push factor stays in the velocity (Eq. 5.2.3, 5.3.1): one solve a step
  split,      ///< the single frame push factor (Sec. 8.1): positions move with f_cv, the stored
              ///< momenta with f_c0 from a second solve without the push
  split_impulse,  ///< Bullet's split impulse (engine/src/push/split_impulse.cpp): the push solved on
                  ///< pseudo-velocities from rest, added to the positions' motion only
  soft,       ///< Box2D v3's soft step (engine/src/push/soft_step.cpp): substeps, soft rows with a
              ///< stiffness (Hz) and damping ratio, then a relax solve without the push
  ngs,        ///< non-linear Gauss-Seidel (engine/src/push/ngs.cpp): a velocity solve without the push,
              ///< then positions moved directly to reduce the overlaps and rod errors
  tgs,        ///< temporal Gauss-Seidel, PhysX 5's eTGS (engine/src/push/tgs.cpp): substeps of rigid
              ///< rows with the push of the current error, then a relax solve without it
  xpbd,       ///< extended position based dynamics for rigid bodies (engine/src/push/xpbd.cpp):
              ///< substeps of positional corrections with compliance, then a velocity pass
  avbd,       ///< Augmented Vertex Block Descent (engine/src/push/avbd.cpp): a primal solve, 6 x 6
              ///< per body, with augmented Lagrangian penalties (Giles et al. 2025)
};

/// Which settings of the solve of A lambda = b a push method reads. Those it does not read
/// change nothing in its runs, so a sweep or a comparison over them would repeat one run.
/// Source: the top comment of each method's file in engine/src/push/.
struct PushReads {
  bool solver = true;          ///< --solver (pgs or jacobi); soft and avbd sweep their own rows, not A lambda = b
  bool friction_model = true;  ///< --friction-model; xpbd and avbd bound friction by mu lambda_n
  bool warm_start = true;      ///< --warm-start; xpbd starts each substep at 0, avbd uses gamma
};

/// What the rest of cps needs to know of a push method, in its row of the push parameter's table
/// (parameters.cpp): the method's file in engine/src/push/, this row, one CMake line and its own
/// parameters' rows are all a new method adds. Source: the top comment of each method's file.
struct PushTraits {
  /// Makes the method (engine/src/push/, internal to the engine). Never nullptr.
  std::unique_ptr<PushMethod> (*make)() = nullptr;
  PushReads reads{};  ///< the settings of the solve it reads
  /// Whether it solves A lambda = b through the step's solver (Sec. 6-7), so that World::step
  /// assembles A (or packs the rows) before it; false for methods that sweep their own rows.
  bool solves_system = true;
  /// The parameter (WorldDef member name, type integer) that sets its substeps a step; empty for
  /// one solve a step. The work estimate counts substeps x iterations.
  std::string_view substeps{};
  /// Whether its push stays in the stored momenta (baumgarte: beta d / dt in the velocity; soft:
  /// the soft rows' springs), so that an energy rise can come from the push itself.
  bool push_in_momenta = false;
  /// Why its push can raise the energy, for the energy-rise warning; empty when
  /// push_in_momenta is false.
  std::string_view energy_rise_cause{};
  /// Whether its push is a velocity in the rows' right-hand side (Sec. 5.3: beta d / dt), so that
  /// the push's work over a step is dt sum_r max(0, lambda_r push_r) (N, m/s); false: the push
  /// is measured as the displacement beyond the velocity, x2 - x1 - v2 dt (m).
  bool push_in_rows = false;
};

/// The candidate nearest to `word` by edit distance (Levenshtein; the first on a tie), for "did
/// you mean" in messages; "" when there are no candidates. No errors.
std::string nearest_name(std::string_view word, const std::vector<std::string>& candidates);

/// The traits of `push` (above), from its row of the push parameter's table. Throws nothing.
const PushTraits& push_traits(PushMode push);

/// The settings `push` reads (push_traits(push).reads). Throws nothing.
PushReads push_reads(PushMode push);

/// The substeps a step of `def`'s push method takes (count, >= 1): the value of its substeps
/// parameter, or 1. Throws nothing.
int push_substeps(const WorldDef& def);

/// The iteration used for A lambda = b.
enum class SolverKind {
  pgs,     ///< projected Gauss-Seidel: new values used at once (Sec. 7.2)
  jacobi,  ///< projected Jacobi: new values used after the sweep (Sec. 7.1)
  /// Graph-coloured projected Gauss-Seidel: PGS with the rows swept colour by colour, the rows of
  /// a colour sharing no movable body (Box2D v3's and Box3D's constraint graph,
  /// engine/src/row_colours.h), each colour shared among WorldDef::threads threads.
  coloured_pgs,
};

/// How friction rows are bounded.
enum class FrictionModel {
  fixed,    ///< the paper's limit +-mu m |g . n| set when the row is built (Sec. 5.4)
  coupled,  ///< +-mu lambda_n with lambda_n the current value of the row's contact row, as
            ///< sequential impulse solvers do (Catto, "Iterative Dynamics", GDC 2005)
};

/// How the orientation follows the angular velocity w = I^-1 l over a step.
enum class RotationUpdate {
  linear,  ///< o += 1/2 [0, w] o dt, then normalise (Eq. 3.2.4)
  exact,   ///< o = [cos(|w| dt / 2), sin(|w| dt / 2) w / |w|] o (Eq. 12.4.1)
};

/// Which of a manifold's clipped points become contact rows (WorldDef::manifold_points).
enum class ManifoldPoints {
  all,   ///< every point of the clipping (up to 8), as the paper's Sec. 4
  four,  ///< reduced to 4 (collision.h, reduce_manifold), as Box3D, Jolt and Bullet do
};

/// Where the soft step's relax (push soft, engine/src/push/soft_step.cpp) starts each substep.
enum class SoftRelax {
  continue_solve,  ///< from the soft solve's accumulated impulses, as Box3D and Box2D v3 relax
  restart,         ///< from the velocities before the soft solve and the last relax's impulses
};

/// Where XPBD (push xpbd, engine/src/push/xpbd.cpp) takes a contact point's friction, in the
/// position pass (static) and the velocity pass (dynamic) alike (WorldDef::xpbd_friction_order).
enum class XpbdFrictionOrder {
  point,     ///< right after the point's own normal, point by point
  manifold,  ///< after the normals of all of its manifold's points, as E. Catto's Solver2D
};

/// Where XPBD's static friction measures a contact point's slip from (WorldDef::xpbd_friction_anchor).
enum class XpbdFrictionAnchor {
  step,     ///< the points' places at the start of the step, as E. Catto's Solver2D
  substep,  ///< their places at the start of the substep
};

/// How A lambda = b is represented while it is solved.
enum class Assembly {
  explicit_matrices,  ///< sparse J, M^-1 and A = J M^-1 J^T built every step (Sec. 6), as the
                      ///< paper states it
  matrix_free,        ///< per body w = M^-1 J^T lambda, O(12) a row update (matrix_free.h)
};

/// How the matrix-free solve stores the rows it sweeps (WorldDef::row_precision): j, M^-1 j^T,
/// the force limits, mu and the coupling of a block run in double, or rounded to float, halving
/// the bytes each sweep reads; lambda, w, b, 1 / A_jj and every sum stay in double either way.
enum class RowPrecision {
  double_precision,  ///< 8-byte j and M^-1 j^T: the paper's numbers (the default)
  single_precision,  ///< 4-byte j, M^-1 j^T, limits and coupling (Box3D's solver is float throughout)
};

/// World parameters, each with its unit and a typical value; the table below gives each one's
/// allowed values. Validate with validate().
struct WorldDef {
  Vec3 gravity = Vec3(0.0, -10.0, 0.0);  ///< m/s^2, each component within +-1e4; paper (0, -10, 0)
  double dt = 1.0 / 60.0;                ///< time step (s) in [1e-6, 1]; the paper uses 1/60
  int iterations = 25;                   ///< solver sweeps per solve in [1, 1e4]; the paper: 25
  double beta = 0.2;                     ///< push factor constant (dimensionless) in [0, 1]; 0.2
  double friction = 0.5;                 ///< friction coefficient mu (dimensionless) >= 0; 0.5
  double restitution = 0.0;              ///< coefficient of restitution eps in [0, 1]; 0
  double restitution_threshold = 1.0;    ///< approach speed (m/s) >= 0 below which no bounce; 1
  PushMode push = PushMode::baumgarte;   ///< Sec. 5.3 (baumgarte), Sec. 8.1 (split) or another
  SolverKind solver = SolverKind::pgs;   ///< Sec. 7.2 PGS, or Jacobi
  FrictionModel friction_model = FrictionModel::fixed;  ///< Sec. 5.4 fixed, or coupled
  RotationUpdate rotation = RotationUpdate::linear;     ///< Eq. 3.2.4, or Eq. 12.4.1
  Assembly assembly = Assembly::matrix_free;  ///< same lambda to round-off; matrix-free is faster
  /// The matrix-free path's rows in double (the default) or float (RowPrecision); float solves a
  /// system whose j and limits are rounded to float (relative 6e-8), so the state differs from double's. The
  /// explicit path has no packed rows: it takes double only (validate()).
  RowPrecision row_precision = RowPrecision::double_precision;
  /// Speculative contact distance (m) >= 0: features closer than this already get a contact row
  /// that lets them close the gap within a step and no further, so resting contacts do not
  /// break and re-form each step. 0 gives the paper's contacts, made only on overlap. Typical:
  /// 1e-3 m for bodies of 0.5 to 3 m. Push xpbd adds its own distance per body on top of it
  /// (engine/src/push/xpbd.cpp).
  double contact_margin = 0.0;
  /// Which clipped points a manifold keeps (ManifoldPoints): all of them (the default, the
  /// paper's Sec. 4) or 4, chosen to keep the contact area (Box3D's reduction; the tolerance is
  /// contact_margin). Fewer rows a step; a face contact's support is kept.
  ManifoldPoints manifold_points = ManifoldPoints::all;
  /// Contact recycling distance (m, >= 0): while two bodies' points have moved relative to each
  /// other by less than this since their manifold was made (and neither has turned by more than
  /// 10 degrees), the collide stage keeps that manifold, its points fixed to the bodies, and
  /// updates only their depths (engine/src/contact_recycling.h). 0 (the default) clips every
  /// step, as the paper. Box3D's: 0.05 m (ten times its linear slop).
  double contact_recycle_distance = 0.0;
  /// Penetration slop (m) >= 0: the push of a contact row (Eq. 5.3.1, and the second solve's
  /// target of Sec. 8.1) corrects only the depth beyond it, beta max(d - slop, 0) / dt, so a
  /// resting contact settles about `slop` deep instead of being pushed out of contact and
  /// re-made every step. 0 (the default) is the paper's push. Not in the paper: Box2D's linear
  /// slop, Jolt's penetration slop. Typical: 0.005 m for bodies of 0.5 to 3 m (Box2D v2.4's
  /// b2_linearSlop); rods have no slop.
  double penetration_slop = 0.0;
  /// Warm starting (Sec. 6.2.3: "the value from the previous frame can be used by caching the
  /// constraint information"), dimensionless in [0, 1]: each row's lambda starts from this
  /// factor times its lambda of the previous steps (the smaller of the last two, so an impact's
  /// impulse is not carried over) when its contact (same body pair and contact feature) or rod
  /// persists, and from 0 when it is new (engine/src/warm_start.h). 0 (the default) is the
  /// paper's initial guess 0 everywhere. Typical 0.8; 1 can feed energy into stiff piles and
  /// chains (docs/findings.md, "Warm starting").
  double warm_start = 0.0;
  /// Split impulse (push split-impulse) only: contacts no deeper than this (m, >= 0) keep their
  /// push in the velocity solve, as Baumgarte; deeper ones are pushed out on pseudo-velocities.
  /// 0 (the default) sends every overlap to the pseudo-velocities. Bullet's
  /// m_splitImpulsePenetrationThreshold is 0.04 m.
  double split_impulse_threshold = 0.0;
  /// Soft step (push soft) only: substeps per step (count, >= 1); each solves with the soft
  /// push, moves the positions, then relaxes. Box3D's default: 4.
  int soft_substeps = 4;
  /// Soft step only: where each substep's relax starts (SoftRelax). Box3D's: continue_solve.
  SoftRelax soft_relax = SoftRelax::continue_solve;
  /// Threads a step runs on (count, in [1, 64]; the calling thread is one of them). The soft
  /// step, and the matrix-free solve of SolverKind::coloured_pgs, share each graph colour's rows
  /// among them (engine/src/constraint_graph.h); under every method the narrow phase, the
  /// matrix-free packing and right-hand side and the soft step's prepare and store are shared
  /// too (engine/src/workers.h); the rest runs on one thread. The result is the same for every
  /// count, bit for bit. Typical: the machine's cores for large scenes; 1 (the default) for
  /// small ones.
  int threads = 1;
  /// Soft step only: the contact rows' stiffness (Hz, >= 0; 0 = rigid rows without push), capped
  /// at an eighth of the substep rate; contacts with a static body get twice it. Box3D's
  /// default: 30.
  double contact_hertz = 30.0;
  /// Soft step only: the contact rows' damping ratio (dimensionless, >= 0; half of it against a
  /// static body). Box3D's default: 10 (strongly overdamped: an overlap is pushed out without
  /// bouncing).
  double contact_damping_ratio = 10.0;
  /// Soft step only: the rods' stiffness (Hz, >= 0; 0 = rigid rods without push), capped at a
  /// quarter of the substep rate. Box3D's default for joints: 60.
  double rod_hertz = 60.0;
  /// Soft step only: the rods' damping ratio (dimensionless, >= 0). Box3D's default for
  /// joints: 2.
  double rod_damping_ratio = 2.0;
  /// Soft step only: the fastest an overlap is pushed out (m/s, > 0). Box2D v3's default
  /// (contactPushMaxSpeed, called contactPushoutVelocity in v3.0): 3.
  double contact_push_max_speed = 3.0;
  /// Non-linear Gauss-Seidel (push ngs) only: position iterations per step (count, >= 1). Box2D
  /// v2.4's default: 3 (Jolt's: 2).
  int position_iterations = 3;
  /// Non-linear Gauss-Seidel only: the largest correction of one contact point or rod in one
  /// position iteration (m, > 0). Box2D v2.4's b2_maxLinearCorrection: 0.2.
  double max_correction = 0.2;
  /// Temporal Gauss-Seidel (push tgs) only: substeps per step (count, >= 1), each a solve with
  /// the push of the current error that moves positions and momenta; the `iterations` are split
  /// over them. PhysX's default position iteration count (its TGS substeps): 4.
  int tgs_substeps = 4;
  /// Push tgs and xpbd only: the fastest an overlap is pushed out (m/s, > 0): tgs caps each
  /// contact row's push, xpbd its pre-stabilisation. PhysX's maxDepenetrationVelocity as Unity
  /// sets it by default: 10.
  double max_depenetration_speed = 10.0;
  /// XPBD (push xpbd) only: substeps per step (count, >= 1), each one sweep of positional
  /// corrections and a velocity pass. Typical: 20 (Mueller et al. 2020 run tens of substeps of
  /// one iteration each).
  int xpbd_substeps = 20;
  /// XPBD only: the rods' compliance alpha (m/N, >= 0), the inverse of their stiffness; 0 (the
  /// default) is a rigid rod, as the source's joints; contacts are always rigid.
  double xpbd_compliance = 0.0;
  /// XPBD only: where a contact point's static and dynamic friction are taken (choice): manifold
  /// (the default) after all of its manifold's normals (E. Catto's Solver2D reading of Mueller et
  /// al. 2020, Secs. 3.5 and 3.6); point right after its own normal.
  XpbdFrictionOrder xpbd_friction_order = XpbdFrictionOrder::manifold;
  /// XPBD only: where static friction measures a point's tangential slip from (choice): step
  /// (the default) its place at the start of the step, so that a substep undoes what earlier
  /// substeps left (Solver2D); substep its place at the start of the substep.
  XpbdFrictionAnchor xpbd_friction_anchor = XpbdFrictionAnchor::step;
  /// AVBD (push avbd) only: the penalty ramp beta (N/m per m of error, >= 0): after each sweep a
  /// row inside its force limits stiffens by beta |C|. The authors' 2D demo: 1e5.
  double avbd_beta = 1.0e5;
  /// AVBD only: alpha (dimensionless, [0, 1]): the rows see C(x) - alpha C(x0), so 1 - alpha of
  /// the error at the start of a step is corrected in it. Demo: 0.99. Unused with
  /// avbd_post_iterations > 0 (then 1 in the sweeps, 0 in the post-stabilisation).
  double avbd_alpha = 0.99;
  /// AVBD only: gamma (dimensionless, [0, 1]): the warm start of lambda (times alpha gamma) and of
  /// the penalty (times gamma) from the last step. Demo: 0.99.
  double avbd_gamma = 0.99;
  /// AVBD only: the smallest penalty (N/m, > 0), a new row's. Demo (PENALTY_MIN): 1.
  double avbd_k_start = 1.0;
  /// AVBD only: the largest penalty (N/m, > 0). Demo (PENALTY_MAX): 1e9.
  double avbd_k_max = 1.0e9;
  /// AVBD only: post-stabilisation sweeps per step (count, [0, 100]) with alpha = 0 after the
  /// velocities are set: they remove the error from the positions only. Demo: 1 (on).
  int avbd_post_iterations = 1;
  bool collision = true;  ///< false: the bodies never collide and the collide stage is skipped
  /// true: after every solve, measure the LCP residual into World::residual(); it costs one pass
  /// over the rows per solve, so it is off unless a report asks for it.
  bool measure_residual = false;

  /// Checks every parameter against the table. Throws std::invalid_argument naming the
  /// parameter, its value and what is allowed ("world parameter dt = 0 is not allowed: it must
  /// be in [1e-06, 1] (s)"). The ranges keep a step finite (see also body.h's ranges).
  void validate() const;
};

/// The kind of value a parameter holds.
enum class ParameterType {
  real,     ///< a finite double in [min, max] (or (min, max] when min_exclusive)
  integer,  ///< an int in [min, max]
  boolean,  ///< true or false
  vector3,  ///< three finite doubles
  choice,   ///< one of the named values of an enum (stored as the enum's int value)
};

/// One named value of a choice parameter.
struct Choice {
  std::string_view name;    ///< as typed and written: "baumgarte"
  int value;                ///< the enum's value, static_cast<int>(PushMode::baumgarte)
  std::string_view source;  ///< where it is defined, for labels ("Sec. 5.3"); may be empty
  /// The paper's name for it (or the field's, where the paper has none), for labels:
  /// "single frame push factor"; may be empty.
  std::string_view title{};
  /// Defined in the paper (Tamis & Maggiore 2015); false for the methods it is compared with.
  bool in_paper = false;
  /// Push choices only: the method's traits and factory (PushTraits); nullptr for the other
  /// parameters' choices.
  const PushTraits* push = nullptr;
};

/// A parameter's value: double (real), int (integer, and choice: the enum's value), bool
/// (boolean) or Vec3 (vector3, in the parameter's unit).
using ParameterValue = std::variant<double, int, bool, Vec3>;

/// One world parameter, defined once.
struct Parameter {
  std::string_view name{};    ///< WorldDef member: "contact_margin"
  std::string_view flag{};    ///< command-line option without "--": "contact-margin"; empty: none
  std::string_view json_key{};  ///< key in run.json and --json, unit as suffix: "contact_margin_m"
  std::string_view unit{};    ///< SI unit ("s", "m", "m/s", "m/s^2"), empty when dimensionless
  ParameterType type = ParameterType::real;
  double min = 0.0;            ///< real, integer, vector3 (each component): smallest allowed value
  double max = 0.0;            ///< real and integer: largest allowed value (may be +inf)
  bool min_exclusive = false;  ///< real: min itself is not allowed (dt > 0)
  std::span<const Choice> choices{};  ///< choice: the allowed names, the default first
  std::string_view help{};     ///< what it means and a typical value, for --help
  /// The paper's name for it with its source, for labels ("push factor constant beta
  /// (Eq. 5.2.3)"); empty: the name with spaces for underscores ("contact margin").
  std::string_view title{};
  ParameterValue (*get)(const WorldDef&) = nullptr;
  void (*set)(WorldDef&, const ParameterValue&) = nullptr;

  /// What is allowed, in words: "finite and > 0 (s)", "in [0, 1]", "one of: baumgarte, split".
  std::string allowed() const;
  /// std::nullopt if `v` is allowed, else why not ("it must be in [0, 1]"). A value of the wrong
  /// alternative (a bool for a real) is not allowed.
  std::optional<std::string> check(const ParameterValue& v) const;
  /// Parses a value as typed on the command line: a decimal number (parse_decimal; a fraction
  /// such as 1/60 too for a time in s), a choice's name, true/false, or "x,y,z". Throws
  /// std::invalid_argument naming the text and what is allowed, for text that does not parse or
  /// a value check() refuses.
  ParameterValue parse(std::string_view text) const;
  /// The value as text, the inverse of parse (reals with 17 significant digits).
  std::string format(const ParameterValue& v) const;
  /// The name of a choice value; throws std::invalid_argument for a value not in choices.
  std::string_view choice_name(int value) const;
  /// The Choice called `name`, or nullptr.
  const Choice* find_choice(std::string_view name) const;
  /// `title`, or the name with spaces for underscores when it has none.
  std::string label() const;
};

/// Parses the whole of `text` as a decimal number ("0.01", "1e-3", "-2"): no hex, no leading
/// '+' or space, no trailing text; "inf" and "nan" parse (check the range after). With
/// allow_fraction, also "a/b" for two such numbers with b != 0 (a time step as 1/60).
/// std::nullopt for anything else. Every numeric option of the command line is read by it.
std::optional<double> parse_decimal(std::string_view text, bool allow_fraction = false);

/// The shortest decimal text that reads back as exactly v ("0.2", "30", "1e-06", "1e+06"):
/// std::to_chars' shortest round-trip form; "inf", "-inf" or "nan" for those. No errors.
std::string shortest_decimal(double v);

/// The table: every WorldDef member once, in WorldDef's order.
std::span<const Parameter> world_parameters();

/// The parameter with this name, flag or JSON key, or nullptr.
const Parameter* find_parameter(std::string_view name);

/// The parameter with this WorldDef member name. Throws std::invalid_argument for an unknown
/// name (a programming error: names are fixed at compile time).
const Parameter& parameter(std::string_view name);

/// Names of the methods, from the table: "baumgarte", "pgs", "fixed", "linear", "matrix-free".
std::string_view name_of(PushMode v);
std::string_view name_of(SolverKind v);
std::string_view name_of(FrictionModel v);
std::string_view name_of(RotationUpdate v);
std::string_view name_of(ManifoldPoints v);
std::string_view name_of(SoftRelax v);
std::string_view name_of(Assembly v);
std::string_view name_of(RowPrecision v);

}  // namespace cps
