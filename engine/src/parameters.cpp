// The parameter table (see parameters.h) and the validation, parsing and formatting it drives.
#include "cps/parameters.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace cps {

// The push methods, one file each in engine/src/push/ (push_method.h).
std::unique_ptr<PushMethod> make_baumgarte();
std::unique_ptr<PushMethod> make_single_frame_push();
std::unique_ptr<PushMethod> make_split_impulse();
std::unique_ptr<PushMethod> make_soft_step();
std::unique_ptr<PushMethod> make_ngs();
std::unique_ptr<PushMethod> make_tgs();
std::unique_ptr<PushMethod> make_xpbd();
std::unique_ptr<PushMethod> make_avbd();

namespace {

template <auto Member>
ParameterValue get_member(const WorldDef& d) {
  using T = std::remove_cvref_t<decltype(d.*Member)>;
  if constexpr (std::is_enum_v<T>) {
    return static_cast<int>(d.*Member);
  } else {
    return d.*Member;
  }
}

template <auto Member>
void set_member(WorldDef& d, const ParameterValue& v) {
  using T = std::remove_cvref_t<decltype(d.*Member)>;
  if constexpr (std::is_enum_v<T>) {
    d.*Member = static_cast<T>(std::get<int>(v));
  } else if constexpr (std::is_same_v<T, double>) {
    // An integer given for a real (set from code as 1 instead of 1.0) is taken as its value.
    d.*Member = std::holds_alternative<int>(v) ? std::get<int>(v) : std::get<double>(v);
  } else {
    d.*Member = std::get<T>(v);
  }
}

// One row per push method (PushTraits, parameters.h): what it reads, whether it solves A lambda = b,
// its substeps parameter and whether its push stays in the momenta, from each file's top comment.
constexpr PushTraits kBaumgarte{
    .make = &make_baumgarte,
    .push_in_momenta = true,
    .energy_rise_cause = "the paper's push factor keeps its push beta d / dt in the velocities, so "
                         "every overlap and rod error it corrects comes back as motion (Sec. 5.3)",
    .push_in_rows = true};
constexpr PushTraits kSplit{.make = &make_single_frame_push};
constexpr PushTraits kSplitImpulse{.make = &make_split_impulse};
constexpr PushTraits kSoft{.make = &make_soft_step,
                           .reads = {.solver = false, .friction_model = true, .warm_start = true},
                           .solves_system = false,
                           .substeps = "soft_substeps",
                           .push_in_momenta = true,
                           .energy_rise_cause = "the soft rows are springs that store and return energy"};
constexpr PushTraits kNgs{.make = &make_ngs};
// At most substeps x iterations biased sweeps, plus the relax's.
constexpr PushTraits kTgs{.make = &make_tgs, .substeps = "tgs_substeps"};
// One sweep a substep, by Gauss-Seidel or Jacobi as --solver says, but not through A lambda = b.
constexpr PushTraits kXpbd{.make = &make_xpbd,
                           .reads = {.solver = true, .friction_model = false, .warm_start = false},
                           .solves_system = false,
                           .substeps = "xpbd_substeps"};
constexpr PushTraits kAvbd{.make = &make_avbd,
                           .reads = {.solver = false, .friction_model = false, .warm_start = false},
                           .solves_system = false};

constexpr std::array kPushChoices = {
    Choice{"baumgarte", static_cast<int>(PushMode::baumgarte), "Sec. 5.3", "push factor",
           /*in_paper=*/true, &kBaumgarte},
    Choice{"split", static_cast<int>(PushMode::split), "Sec. 8.1", "single frame push factor",
           /*in_paper=*/true, &kSplit},
    Choice{"split-impulse", static_cast<int>(PushMode::split_impulse), "Bullet", "split impulse",
           /*in_paper=*/false, &kSplitImpulse},
    Choice{"soft", static_cast<int>(PushMode::soft), "Box3D", "soft step", /*in_paper=*/false, &kSoft},
    Choice{"ngs", static_cast<int>(PushMode::ngs), "Box2D v2.4", "non-linear Gauss-Seidel",
           /*in_paper=*/false, &kNgs},
    Choice{"tgs", static_cast<int>(PushMode::tgs), "PhysX 5", "temporal Gauss-Seidel",
           /*in_paper=*/false, &kTgs},
    Choice{"xpbd", static_cast<int>(PushMode::xpbd), "Mueller et al. 2020", "extended position based dynamics",
           /*in_paper=*/false, &kXpbd},
    Choice{"avbd", static_cast<int>(PushMode::avbd), "Giles et al. 2025",
           "augmented vertex block descent", /*in_paper=*/false, &kAvbd},
};
constexpr std::array kSolverChoices = {
    Choice{"pgs", static_cast<int>(SolverKind::pgs), "Sec. 7.2", "projected Gauss-Seidel"},
    Choice{"jacobi", static_cast<int>(SolverKind::jacobi), "Sec. 7.1", "projected Jacobi"},
    Choice{"coloured-pgs", static_cast<int>(SolverKind::coloured_pgs), "Box2D v3",
           "graph-coloured projected Gauss-Seidel"},
};
constexpr std::array kFrictionModelChoices = {
    Choice{"fixed", static_cast<int>(FrictionModel::fixed), "Sec. 5.4", "friction limit mu m |g.n|"},
    Choice{"coupled", static_cast<int>(FrictionModel::coupled), "", "friction limit mu lambda_n"},
};
constexpr std::array kManifoldPointsChoices = {
    Choice{"all", static_cast<int>(ManifoldPoints::all), "Sec. 4", "every clipped point (up to 8)"},
    Choice{"4", static_cast<int>(ManifoldPoints::four), "Box3D",
           "reduced to 4 points that keep the contact area"},
};
constexpr std::array kSoftRelaxChoices = {
    Choice{"continue", static_cast<int>(SoftRelax::continue_solve), "Box3D",
           "relax from the soft solve's impulses"},
    Choice{"restart", static_cast<int>(SoftRelax::restart), "Sec. 8.1",
           "relax from the substep's start and the last relax's impulses"},
};
constexpr std::array kXpbdFrictionOrderChoices = {
    Choice{"manifold", static_cast<int>(XpbdFrictionOrder::manifold), "Solver2D",
           "a manifold's friction after all of its normals"},
    Choice{"point", static_cast<int>(XpbdFrictionOrder::point), "Mueller et al. 2020",
           "each point's friction right after its normal"},
};
constexpr std::array kXpbdFrictionAnchorChoices = {
    Choice{"step", static_cast<int>(XpbdFrictionAnchor::step), "Solver2D",
           "the slip since the start of the step"},
    Choice{"substep", static_cast<int>(XpbdFrictionAnchor::substep), "Mueller et al. 2020",
           "the slip since the start of the substep"},
};
constexpr std::array kRotationChoices = {
    Choice{"linear", static_cast<int>(RotationUpdate::linear), "Eq. 3.2.4", "linear orientation update"},
    Choice{"exact", static_cast<int>(RotationUpdate::exact), "Eq. 12.4.1", "axis-angle orientation update"},
};
constexpr std::array kAssemblyChoices = {
    Choice{"matrix-free", static_cast<int>(Assembly::matrix_free), "", "matrix-free"},
    Choice{"explicit", static_cast<int>(Assembly::explicit_matrices), "Sec. 6", "explicit J, M^-1 and A"},
};
constexpr std::array kRowPrecisionChoices = {
    Choice{"double", static_cast<int>(RowPrecision::double_precision), "", "rows in double"},
    Choice{"float", static_cast<int>(RowPrecision::single_precision), "Box3D", "rows in float"},
};

// Every WorldDef member, in its order. Reals and integers are finite and in [min, max].
const std::array kParameters = {
    Parameter{.name = "gravity",
              .flag = "",
              .json_key = "gravity_mps2",
              .unit = "m/s^2",
              .type = ParameterType::vector3,
              .min = -1.0e4,
              .max = 1.0e4,
              .help = "gravitational acceleration; the paper uses (0, -10, 0)",
              .get = &get_member<&WorldDef::gravity>,
              .set = &set_member<&WorldDef::gravity>},
    Parameter{.name = "dt",
              .flag = "dt",
              .json_key = "dt_s",
              .unit = "s",
              .type = ParameterType::real,
              .min = 1.0e-6,
              .max = 1.0,
              .help = "time step; the paper uses 1/60",
              .title = "time step dt",
              .get = &get_member<&WorldDef::dt>,
              .set = &set_member<&WorldDef::dt>},
    Parameter{.name = "iterations",
              .flag = "iterations",
              .json_key = "iterations",
              .unit = "",
              .type = ParameterType::integer,
              .min = 1.0,
              .max = 10000.0,
              .help = "solver sweeps per solve of A lambda = b; the paper uses 25",
              .title = "solver iterations (Sec. 7)",
              .get = &get_member<&WorldDef::iterations>,
              .set = &set_member<&WorldDef::iterations>},
    Parameter{.name = "beta",
              .flag = "beta",
              .json_key = "beta",
              .unit = "",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0,
              .help = "push factor constant beta (Eq. 5.2.3); the paper uses 0.2",
              .title = "push factor constant beta (Eq. 5.2.3)",
              .get = &get_member<&WorldDef::beta>,
              .set = &set_member<&WorldDef::beta>},
    Parameter{.name = "friction",
              .flag = "friction",
              .json_key = "friction",
              .unit = "",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .help = "friction coefficient mu (Sec. 5.4); 0 builds no friction rows; scenes use 0.5",
              .title = "friction coefficient mu (Sec. 5.4)",
              .get = &get_member<&WorldDef::friction>,
              .set = &set_member<&WorldDef::friction>},
    Parameter{.name = "restitution",
              .flag = "restitution",
              .json_key = "restitution",
              .unit = "",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0,
              .help = "coefficient of restitution eps (Eq. 8.2.1); scenes use 0",
              .title = "coefficient of restitution eps (Eq. 8.2.1)",
              .get = &get_member<&WorldDef::restitution>,
              .set = &set_member<&WorldDef::restitution>},
    Parameter{.name = "restitution_threshold",
              .flag = "restitution-threshold",
              .json_key = "restitution_threshold_mps",
              .unit = "m/s",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .help = "contacts approaching slower than this get no restitution, so resting "
                      "contacts do not bounce; typical 1",
              .get = &get_member<&WorldDef::restitution_threshold>,
              .set = &set_member<&WorldDef::restitution_threshold>},
    Parameter{.name = "push",
              .flag = "push",
              .json_key = "push",
              .type = ParameterType::choice,
              .choices = kPushChoices,
              .help = "baumgarte: the push factor kept in the velocity (Sec. 5); split: the single "
                      "frame push factor, two solves (Sec. 8.1); split-impulse: Bullet's split "
                      "impulse, the push on pseudo-velocities; soft: Box3D's soft step, "
                      "substeps with soft rows and relax; ngs: non-linear Gauss-Seidel position "
                      "projection (Box2D v2.4); tgs: temporal Gauss-Seidel (PhysX 5), substeps with the "
                      "push then a relax; xpbd: extended position based dynamics (Mueller et al. "
                      "2020), substeps of positional corrections; avbd: augmented vertex block "
                      "descent, a primal solve per body (Giles et al. 2025)",
              .title = "constraint correction",
              .get = &get_member<&WorldDef::push>,
              .set = &set_member<&WorldDef::push>},
    Parameter{.name = "solver",
              .flag = "solver",
              .json_key = "solver",
              .type = ParameterType::choice,
              .choices = kSolverChoices,
              .help = "pgs: projected Gauss-Seidel (Sec. 7.2); jacobi: projected Jacobi (Sec. 7.1); "
                      "coloured-pgs: PGS with the rows swept by graph colour (Box2D v3's "
                      "constraint graph), each colour shared among --threads (push xpbd sweeps "
                      "it as pgs)",
              .title = "solver",
              .get = &get_member<&WorldDef::solver>,
              .set = &set_member<&WorldDef::solver>},
    Parameter{.name = "friction_model",
              .flag = "friction-model",
              .json_key = "friction_model",
              .type = ParameterType::choice,
              .choices = kFrictionModelChoices,
              .help = "fixed: the paper's limit mu m |g.n| (Sec. 5.4); coupled: mu times the "
                      "contact row's lambda",
              .title = "friction model",
              .get = &get_member<&WorldDef::friction_model>,
              .set = &set_member<&WorldDef::friction_model>},
    Parameter{.name = "rotation",
              .flag = "rotation",
              .json_key = "rotation",
              .type = ParameterType::choice,
              .choices = kRotationChoices,
              .help = "linear: Eq. 3.2.4 then normalise; exact: the axis-angle step of Eq. 12.4.1",
              .title = "orientation update",
              .get = &get_member<&WorldDef::rotation>,
              .set = &set_member<&WorldDef::rotation>},
    Parameter{.name = "assembly",
              .flag = "assembly",
              .json_key = "assembly",
              .type = ParameterType::choice,
              .choices = kAssemblyChoices,
              .help = "matrix-free: w = M^-1 J^T lambda per body (the default); explicit: sparse "
                      "J, M^-1 and A = J M^-1 J^T as in Sec. 6; the same lambda to round-off",
              .get = &get_member<&WorldDef::assembly>,
              .set = &set_member<&WorldDef::assembly>},
    Parameter{.name = "row_precision",
              .flag = "row-precision",
              .json_key = "row_precision",
              .type = ParameterType::choice,
              .choices = kRowPrecisionChoices,
              .help = "how the matrix-free solve stores the rows it sweeps: double (the paper's "
                      "numbers) or float (j, M^-1 j^T and the limits rounded to float, in half their bytes; "
                      "lambda and every sum stay double; another state); --assembly explicit "
                      "takes double only",
              .title = "row precision",
              .get = &get_member<&WorldDef::row_precision>,
              .set = &set_member<&WorldDef::row_precision>},
    Parameter{.name = "contact_margin",
              .flag = "contact-margin",
              .json_key = "contact_margin_m",
              .unit = "m",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .help = "speculative contact distance; 0 = contacts only on overlap, as in the "
                      "paper (push xpbd adds its own, 2 dt times each body's speed); typical "
                      "0.001 for bodies of 0.5 to 3 m",
              .get = &get_member<&WorldDef::contact_margin>,
              .set = &set_member<&WorldDef::contact_margin>},
    Parameter{.name = "manifold_points",
              .flag = "manifold-points",
              .json_key = "manifold_points",
              .type = ParameterType::choice,
              .choices = kManifoldPointsChoices,
              .help = "which clipped points of a manifold become contact rows: all (up to 8, as "
                      "in Sec. 4) or 4 that keep the contact area (Box3D's reduction, tolerance "
                      "contact_margin)",
              .get = &get_member<&WorldDef::manifold_points>,
              .set = &set_member<&WorldDef::manifold_points>},
    Parameter{.name = "contact_recycle_distance",
              .flag = "contact-recycle-distance",
              .json_key = "contact_recycle_distance_m",
              .unit = "m",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .help = "contact recycling: a manifold is kept, its anchors as made and its depths "
                      "updated, while its "
                      "bodies move relative to each other by less than this since it was made "
                      "(and turn less than 10 degrees); 0 = clip every step, as the paper; "
                      "Box3D's 0.05",
              .get = &get_member<&WorldDef::contact_recycle_distance>,
              .set = &set_member<&WorldDef::contact_recycle_distance>},
    Parameter{.name = "penetration_slop",
              .flag = "penetration-slop",
              .json_key = "penetration_slop_m",
              .unit = "m",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .help = "penetration slop: the push corrects only the depth beyond it, so resting "
                      "contacts settle this deep instead of being pushed apart and re-made each "
                      "step; 0 = the paper's push; typical 0.005 for bodies of 0.5 to 3 m",
              .get = &get_member<&WorldDef::penetration_slop>,
              .set = &set_member<&WorldDef::penetration_slop>},
    Parameter{.name = "warm_start",
              .flag = "warm-start",
              .json_key = "warm_start",
              .unit = "",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0,
              .help = "warm starting (Sec. 6.2.3): each row's lambda starts from this factor times "
                      "its lambda of the previous steps when its contact or rod persists; 0 = the "
                      "paper's initial guess 0; typical 0.8 (1 can feed energy into stiff piles "
                      "and chains)",
              .title = "warm start factor (Sec. 6.2.3)",
              .get = &get_member<&WorldDef::warm_start>,
              .set = &set_member<&WorldDef::warm_start>},
    Parameter{.name = "split_impulse_threshold",
              .flag = "split-impulse-threshold",
              .json_key = "split_impulse_threshold_m",
              .unit = "m",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .help = "push split-impulse: contacts no deeper than this keep their push in the "
                      "velocity; 0 = every overlap on pseudo-velocities; Bullet's 0.04",
              .get = &get_member<&WorldDef::split_impulse_threshold>,
              .set = &set_member<&WorldDef::split_impulse_threshold>},
    Parameter{.name = "soft_substeps",
              .flag = "soft-substeps",
              .json_key = "soft_substeps",
              .unit = "",
              .type = ParameterType::integer,
              .min = 1.0,
              .max = 1000.0,
              .help = "push soft: substeps per step, each a soft solve, a position update and a "
                      "relax solve; Box3D's 4",
              .get = &get_member<&WorldDef::soft_substeps>,
              .set = &set_member<&WorldDef::soft_substeps>},
    Parameter{.name = "soft_relax",
              .flag = "soft-relax",
              .json_key = "soft_relax",
              .type = ParameterType::choice,
              .choices = kSoftRelaxChoices,
              .help = "push soft: where each substep's relax starts; continue: from the soft "
                      "solve's impulses and velocities (Box3D's); restart: from the velocities "
                      "before the soft solve and the last relax's impulses, as the single frame "
                      "push factor's second solve (Sec. 8.1)",
              .get = &get_member<&WorldDef::soft_relax>,
              .set = &set_member<&WorldDef::soft_relax>},
    Parameter{.name = "threads",
              .flag = "threads",
              .json_key = "threads",
              .unit = "",
              .type = ParameterType::integer,
              .min = 1.0,
              .max = 64.0,
              .help = "threads a step runs on: push soft, and --solver coloured-pgs with "
                      "--assembly matrix-free, share each graph colour's rows among them; the "
                      "narrow phase, the matrix-free packing and right-hand side and the soft "
                      "step's prepare and store are shared under every method; the rest runs "
                      "on one; the same result for every count; typical: the machine's cores "
                      "for large scenes",
              .get = &get_member<&WorldDef::threads>,
              .set = &set_member<&WorldDef::threads>},
    Parameter{.name = "contact_hertz",
              .flag = "contact-hertz",
              .json_key = "contact_hertz_hz",
              .unit = "Hz",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .help = "push soft: contact stiffness, capped at an eighth of the substep rate "
                      "(twice it against a static body); 0 = rigid, no push; Box3D's 30",
              .get = &get_member<&WorldDef::contact_hertz>,
              .set = &set_member<&WorldDef::contact_hertz>},
    Parameter{.name = "contact_damping_ratio",
              .flag = "contact-damping-ratio",
              .json_key = "contact_damping_ratio",
              .unit = "",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .help = "push soft: contact damping ratio (half of it against a static body); Box3D's 10",
              .get = &get_member<&WorldDef::contact_damping_ratio>,
              .set = &set_member<&WorldDef::contact_damping_ratio>},
    Parameter{.name = "rod_hertz",
              .flag = "rod-hertz",
              .json_key = "rod_hertz_hz",
              .unit = "Hz",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .help = "push soft: rod stiffness, capped at a quarter of the substep rate; 0 = rigid, no "
                      "push; Box3D's joint default 60",
              .get = &get_member<&WorldDef::rod_hertz>,
              .set = &set_member<&WorldDef::rod_hertz>},
    Parameter{.name = "rod_damping_ratio",
              .flag = "rod-damping-ratio",
              .json_key = "rod_damping_ratio",
              .unit = "",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .help = "push soft: rod damping ratio; Box3D's joint default 2",
              .get = &get_member<&WorldDef::rod_damping_ratio>,
              .set = &set_member<&WorldDef::rod_damping_ratio>},
    Parameter{.name = "contact_push_max_speed",
              .flag = "contact-push-max-speed",
              .json_key = "contact_push_max_speed_mps",
              .unit = "m/s",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .min_exclusive = true,
              .help = "push soft: the fastest an overlap is pushed out; Box3D's 3",
              .get = &get_member<&WorldDef::contact_push_max_speed>,
              .set = &set_member<&WorldDef::contact_push_max_speed>},
    Parameter{.name = "position_iterations",
              .flag = "position-iterations",
              .json_key = "position_iterations",
              .unit = "",
              .type = ParameterType::integer,
              .min = 1.0,
              .max = 10000.0,
              .help = "push ngs: position iterations per step; Box2D v2.4's 3, Jolt's 2",
              .get = &get_member<&WorldDef::position_iterations>,
              .set = &set_member<&WorldDef::position_iterations>},
    Parameter{.name = "max_correction",
              .flag = "max-correction",
              .json_key = "max_correction_m",
              .unit = "m",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .min_exclusive = true,
              .help = "push ngs: the largest correction of a contact or rod in one position "
                      "iteration; Box2D v2.4's 0.2",
              .get = &get_member<&WorldDef::max_correction>,
              .set = &set_member<&WorldDef::max_correction>},
    Parameter{.name = "tgs_substeps",
              .flag = "tgs-substeps",
              .json_key = "tgs_substeps",
              .unit = "",
              .type = ParameterType::integer,
              .min = 1.0,
              .max = 1000.0,
              .help = "push tgs: substeps per step, each a solve with the push of the current error "
                      "(the iterations split over them), then one relax solve; PhysX's 4",
              .get = &get_member<&WorldDef::tgs_substeps>,
              .set = &set_member<&WorldDef::tgs_substeps>},
    Parameter{.name = "max_depenetration_speed",
              .flag = "max-depenetration-speed",
              .json_key = "max_depenetration_speed_mps",
              .unit = "m/s",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .min_exclusive = true,
              .help = "push tgs and xpbd: the fastest an overlap is pushed out; PhysX's "
                      "maxDepenetrationVelocity, 10 as Unity sets it",
              .get = &get_member<&WorldDef::max_depenetration_speed>,
              .set = &set_member<&WorldDef::max_depenetration_speed>},
    Parameter{.name = "xpbd_substeps",
              .flag = "xpbd-substeps",
              .json_key = "xpbd_substeps",
              .unit = "",
              .type = ParameterType::integer,
              .min = 1.0,
              .max = 1000.0,
              .help = "push xpbd: substeps per step, each one sweep of positional corrections "
                      "and a velocity pass; typical 20",
              .get = &get_member<&WorldDef::xpbd_substeps>,
              .set = &set_member<&WorldDef::xpbd_substeps>},
    Parameter{.name = "xpbd_friction_order",
              .flag = "xpbd-friction-order",
              .json_key = "xpbd_friction_order",
              .type = ParameterType::choice,
              .choices = kXpbdFrictionOrderChoices,
              .help = "push xpbd: where a contact point's static and dynamic friction are taken; "
                      "manifold: after all of its manifold's normals (E. Catto's Solver2D); "
                      "point: right after its own normal",
              .get = &get_member<&WorldDef::xpbd_friction_order>,
              .set = &set_member<&WorldDef::xpbd_friction_order>},
    Parameter{.name = "xpbd_friction_anchor",
              .flag = "xpbd-friction-anchor",
              .json_key = "xpbd_friction_anchor",
              .type = ParameterType::choice,
              .choices = kXpbdFrictionAnchorChoices,
              .help = "push xpbd: where static friction measures a contact point's slip from; "
                      "step: its place at the start of the step (E. Catto's Solver2D); substep: "
                      "at the start of the substep",
              .get = &get_member<&WorldDef::xpbd_friction_anchor>,
              .set = &set_member<&WorldDef::xpbd_friction_anchor>},
    Parameter{.name = "xpbd_compliance",
              .flag = "xpbd-compliance",
              .json_key = "xpbd_compliance_m_per_n",
              .unit = "m/N",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e6,
              .help = "push xpbd: the rods' compliance (inverse stiffness); 0 = rigid rods, as the "
                      "source's joints",
              .get = &get_member<&WorldDef::xpbd_compliance>,
              .set = &set_member<&WorldDef::xpbd_compliance>},
    Parameter{.name = "avbd_beta",
              .flag = "avbd-beta",
              .json_key = "avbd_beta_n_per_m2",
              .unit = "N/m^2",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e12,
              .min_exclusive = false,
              .help = "push avbd: penalty ramp per metre of error after each sweep; the AVBD demo's 1e5",
              .get = &get_member<&WorldDef::avbd_beta>,
              .set = &set_member<&WorldDef::avbd_beta>},
    Parameter{.name = "avbd_alpha",
              .flag = "avbd-alpha",
              .json_key = "avbd_alpha",
              .unit = "",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0,
              .min_exclusive = false,
              .help = "push avbd: rows see C(x) - alpha C(x0) without post-stabilisation; demo 0.99",
              .get = &get_member<&WorldDef::avbd_alpha>,
              .set = &set_member<&WorldDef::avbd_alpha>},
    Parameter{.name = "avbd_gamma",
              .flag = "avbd-gamma",
              .json_key = "avbd_gamma",
              .unit = "",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0,
              .min_exclusive = false,
              .help = "push avbd: warm start decay of lambda and the penalty between steps; demo 0.99",
              .get = &get_member<&WorldDef::avbd_gamma>,
              .set = &set_member<&WorldDef::avbd_gamma>},
    Parameter{.name = "avbd_k_start",
              .flag = "avbd-k-start",
              .json_key = "avbd_k_start_n_per_m",
              .unit = "N/m",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e15,
              .min_exclusive = true,
              .help = "push avbd: smallest penalty, a new row's; demo 1",
              .get = &get_member<&WorldDef::avbd_k_start>,
              .set = &set_member<&WorldDef::avbd_k_start>},
    Parameter{.name = "avbd_k_max",
              .flag = "avbd-k-max",
              .json_key = "avbd_k_max_n_per_m",
              .unit = "N/m",
              .type = ParameterType::real,
              .min = 0.0,
              .max = 1.0e15,
              .min_exclusive = true,
              .help = "push avbd: largest penalty; demo 1e9",
              .get = &get_member<&WorldDef::avbd_k_max>,
              .set = &set_member<&WorldDef::avbd_k_max>},
    Parameter{.name = "avbd_post_iterations",
              .flag = "avbd-post-iterations",
              .json_key = "avbd_post_iterations",
              .unit = "",
              .type = ParameterType::integer,
              .min = 0.0,
              .max = 100.0,
              .help = "push avbd: post-stabilisation sweeps (positions only); 0 = off; demo 1",
              .get = &get_member<&WorldDef::avbd_post_iterations>,
              .set = &set_member<&WorldDef::avbd_post_iterations>},
    Parameter{.name = "collision",
              .flag = "",
              .json_key = "collision",
              .type = ParameterType::boolean,
              .help = "false: bodies never collide",
              .get = &get_member<&WorldDef::collision>,
              .set = &set_member<&WorldDef::collision>},
    Parameter{.name = "measure_residual",
              .flag = "",
              .json_key = "measure_residual",
              .type = ParameterType::boolean,
              .help = "measure the LCP residual of every solve (costs a pass over the rows)",
              .get = &get_member<&WorldDef::measure_residual>,
              .set = &set_member<&WorldDef::measure_residual>},
};

std::string unit_suffix(const Parameter& p) {
  return p.unit.empty() ? std::string() : " (" + std::string(p.unit) + ")";
}

}  // namespace

std::string shortest_decimal(double v) {
  char text[40];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, v);
  return ec == std::errc() ? std::string(text, end) : std::string("nan");
}

std::optional<double> parse_decimal(std::string_view text, bool allow_fraction) {
  const auto whole = [](std::string_view t) -> std::optional<double> {
    double value = 0.0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (t.empty() || ec != std::errc() || end != t.data() + t.size()) return std::nullopt;
    return value;
  };
  const std::size_t slash = text.find('/');
  if (!allow_fraction || slash == std::string_view::npos) return whole(text);
  const std::optional<double> a = whole(text.substr(0, slash));
  const std::optional<double> b = whole(text.substr(slash + 1));
  if (!a || !b || !std::isfinite(*a) || !std::isfinite(*b) || *b == 0.0) return std::nullopt;
  return *a / *b;
}

std::string nearest_name(std::string_view word, const std::vector<std::string>& candidates) {
  // Levenshtein distance, one row at a time.
  const auto distance = [](std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      std::size_t diagonal = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const std::size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
        diagonal = up;
      }
    }
    return row[b.size()];
  };
  std::string best;
  std::size_t best_distance = std::string::npos;
  for (const std::string& c : candidates) {
    const std::size_t d = distance(word, c);
    if (d < best_distance) {
      best = c;
      best_distance = d;
    }
  }
  return best;
}

std::string Parameter::allowed() const {
  switch (type) {
    case ParameterType::real: {
      std::string s = "finite and ";
      if (max == kInfinity) {
        s += (min_exclusive ? "> " : ">= ") + shortest_decimal(min);
      } else {
        s = std::string(min_exclusive ? "in (" : "in [") + shortest_decimal(min) + ", " +
            shortest_decimal(max) + "]";
      }
      return s + unit_suffix(*this);
    }
    case ParameterType::integer:
      return "a whole number in [" + shortest_decimal(min) + ", " + shortest_decimal(max) + "]";
    case ParameterType::boolean:
      return "true or false";
    case ParameterType::vector3:
      return "three numbers x,y,z, each in [" + shortest_decimal(min) + ", " +
             shortest_decimal(max) + "]" + unit_suffix(*this);
    case ParameterType::choice: {
      std::string s = "one of: ";
      for (std::size_t i = 0; i < choices.size(); ++i) {
        s += (i > 0 ? ", " : "") + std::string(choices[i].name);
      }
      return s;
    }
  }
  return {};
}

std::optional<std::string> Parameter::check(const ParameterValue& v) const {
  const std::string must = "it must be " + allowed();
  switch (type) {
    case ParameterType::real: {
      if (!std::holds_alternative<double>(v) && !std::holds_alternative<int>(v)) return must;
      const double x = std::holds_alternative<int>(v) ? std::get<int>(v) : std::get<double>(v);
      // isfinite first: an ordered comparison with NaN would raise FE_INVALID.
      if (!std::isfinite(x)) return must;
      if (!(min_exclusive ? x > min : x >= min) || x > max) return must;
      return std::nullopt;
    }
    case ParameterType::integer: {
      if (!std::holds_alternative<int>(v)) return must;
      const int x = std::get<int>(v);
      if (x < min || x > max) return must;
      return std::nullopt;
    }
    case ParameterType::boolean:
      if (!std::holds_alternative<bool>(v)) return must;
      return std::nullopt;
    case ParameterType::vector3: {
      if (!std::holds_alternative<Vec3>(v)) return must;
      const Vec3& x = std::get<Vec3>(v);
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(x[k]) || x[k] < min || x[k] > max) return must;
      }
      return std::nullopt;
    }
    case ParameterType::choice:
      if (!std::holds_alternative<int>(v)) return must;
      for (const Choice& c : choices) {
        if (c.value == std::get<int>(v)) return std::nullopt;
      }
      return must;
  }
  return must;
}

ParameterValue Parameter::parse(std::string_view text) const {
  const auto refuse = [&](const std::string& why) -> std::invalid_argument {
    const std::string shown = flag.empty() ? std::string(name) : "--" + std::string(flag);
    return std::invalid_argument(shown + " " + std::string(text) + ": " + why);
  };
  ParameterValue v;
  switch (type) {
    case ParameterType::real: {
      const bool time = unit == "s";
      const std::optional<double> x = parse_decimal(text, time);
      if (!x) {
        throw refuse(std::string("not a number; give a decimal number") +
                     (time ? " or a fraction such as 1/60" : "") + ", " + allowed());
      }
      v = *x;
      break;
    }
    case ParameterType::integer: {
      int x = 0;
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), x);
      if (ec != std::errc() || end != text.data() + text.size() || text.empty()) {
        throw refuse("not a whole number; give " + allowed());
      }
      v = x;
      break;
    }
    case ParameterType::boolean:
      if (text == "true") {
        v = true;
      } else if (text == "false") {
        v = false;
      } else {
        throw refuse("give true or false");
      }
      break;
    case ParameterType::vector3: {
      Vec3 x;
      std::size_t start = 0;
      for (int k = 0; k < 3; ++k) {
        const std::size_t comma = k < 2 ? text.find(',', start) : text.size();
        const std::optional<double> c =
            comma == std::string_view::npos ? std::nullopt : parse_decimal(text.substr(start, comma - start));
        if (!c) throw refuse("give " + allowed());
        x[k] = *c;
        start = comma + 1;
      }
      v = x;
      break;
    }
    case ParameterType::choice: {
      const Choice* c = find_choice(text);
      if (c == nullptr) {
        std::vector<std::string> names;
        for (const Choice& choice : choices) names.emplace_back(choice.name);
        throw refuse("'" + std::string(text) + "' is not " + allowed() + "; did you mean '" +
                     nearest_name(text, names) + "'?");
      }
      v = c->value;
      break;
    }
  }
  if (const std::optional<std::string> why = check(v)) throw refuse(*why);
  return v;
}

std::string Parameter::format(const ParameterValue& v) const {
  if (type == ParameterType::choice && std::holds_alternative<int>(v)) {
    for (const Choice& c : choices) {
      if (c.value == std::get<int>(v)) return std::string(c.name);
    }
  }
  if (std::holds_alternative<double>(v)) return shortest_decimal(std::get<double>(v));
  if (std::holds_alternative<int>(v)) return std::to_string(std::get<int>(v));
  if (std::holds_alternative<bool>(v)) return std::get<bool>(v) ? "true" : "false";
  const Vec3& x = std::get<Vec3>(v);
  return shortest_decimal(x.x()) + "," + shortest_decimal(x.y()) + "," + shortest_decimal(x.z());
}

std::string_view Parameter::choice_name(int value) const {
  for (const Choice& c : choices) {
    if (c.value == value) return c.name;
  }
  throw std::invalid_argument("parameter " + std::string(name) + " has no value " +
                              std::to_string(value));
}

const Choice* Parameter::find_choice(std::string_view choice) const {
  for (const Choice& c : choices) {
    if (c.name == choice) return &c;
  }
  return nullptr;
}

std::string Parameter::label() const {
  if (!title.empty()) return std::string(title);
  std::string s(name);
  std::replace(s.begin(), s.end(), '_', ' ');
  return s;
}

std::span<const Parameter> world_parameters() { return kParameters; }

const Parameter* find_parameter(std::string_view name) {
  for (const Parameter& p : kParameters) {
    if (p.name == name || (!p.flag.empty() && p.flag == name) || p.json_key == name) return &p;
  }
  return nullptr;
}

const Parameter& parameter(std::string_view name) {
  for (const Parameter& p : kParameters) {
    if (p.name == name) return p;
  }
  throw std::invalid_argument("no world parameter is called '" + std::string(name) + "'");
}

const PushTraits& push_traits(PushMode push) {
  for (const Choice& c : kPushChoices) {
    if (c.value == static_cast<int>(push)) return *c.push;
  }
  return *kPushChoices[0].push;  // not reached: every PushMode has its row (checked by the tests)
}

PushReads push_reads(PushMode push) { return push_traits(push).reads; }

int push_substeps(const WorldDef& def) {
  const std::string_view substeps = push_traits(def.push).substeps;
  return substeps.empty() ? 1 : std::get<int>(parameter(substeps).get(def));
}

std::string_view name_of(PushMode v) { return parameter("push").choice_name(static_cast<int>(v)); }
std::string_view name_of(SolverKind v) { return parameter("solver").choice_name(static_cast<int>(v)); }
std::string_view name_of(FrictionModel v) {
  return parameter("friction_model").choice_name(static_cast<int>(v));
}
std::string_view name_of(RotationUpdate v) {
  return parameter("rotation").choice_name(static_cast<int>(v));
}
std::string_view name_of(ManifoldPoints v) {
  return parameter("manifold_points").choice_name(static_cast<int>(v));
}
std::string_view name_of(SoftRelax v) {
  return parameter("soft_relax").choice_name(static_cast<int>(v));
}
std::string_view name_of(Assembly v) { return parameter("assembly").choice_name(static_cast<int>(v)); }
std::string_view name_of(RowPrecision v) {
  return parameter("row_precision").choice_name(static_cast<int>(v));
}

void WorldDef::validate() const {
  for (const Parameter& p : kParameters) {
    const ParameterValue v = p.get(*this);
    if (const std::optional<std::string> why = p.check(v)) {
      throw std::invalid_argument("world parameter " + std::string(p.name) + " = " + p.format(v) +
                                  " is not allowed: " + *why);
    }
  }
  if (assembly == Assembly::explicit_matrices && row_precision != RowPrecision::double_precision) {
    throw std::invalid_argument("world parameter row_precision = " + std::string(name_of(row_precision)) +
                                " is not allowed with assembly = explicit, which assembles J in "
                                "double; give row_precision double, or assembly matrix-free");
  }
}

}  // namespace cps
