// The Python module `cps`: the scenes, a run's step and state, its metrics and state hash, and
// its pictures as numpy arrays, over the same engine, scenes and renderer as the `cps` command
// (docs/python.md). Errors: bad input raises ValueError with the command's message, a file that
// cannot be read OSError; no call lets a C++ exception or a crash reach the interpreter.
#include "avbd_demo.h"
#include "box3d_pyramids.h"
#include "command.h"
#include "options/options.h"
#include "pictures/draw.h"
#include "scene.h"
#include "scene_file.h"
#include "state_hash.h"
#include "usage_error.h"

#include "cps/parameters.h"
#include "cps/render/renderer.h"
#include "cps/world.h"

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace py = pybind11;

namespace cps::python {
namespace {

// A number as the command line takes it: 17 significant digits, so it parses back exactly.
std::string decimal(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

// A JSON value as the Python object json.loads gives.
py::object to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

// One row of scenes(): a table scene or a family.
py::dict scene_row(const scenes::Scene& s, const char* group) {
  py::dict d;
  d["name"] = std::string(s.name);
  d["group"] = group;
  d["default_seconds"] = s.default_seconds;
  d["summary"] = std::string(s.summary);
  return d;
}

py::list scene_list() {
  py::list out;
  for (const scenes::Scene& s : scenes::paper_scenes()) out.append(scene_row(s, "paper"));
  for (const scenes::Scene& s : scenes::stress_scenes()) out.append(scene_row(s, "stress"));
  for (const scenes::Scene& s : scenes::benchmark_scenes()) out.append(scene_row(s, "benchmark"));
  for (const scenes::Scene& s : scenes::avbd_demo_scenes()) out.append(scene_row(s, "avbd demo"));
  for (const std::string_view name : scenes::example_scene_names()) {
    out.append(scene_row(*scenes::find_example_scene(name), "example"));
  }
  return out;
}

py::list parameter_list() {
  py::list out;
  WorldDef defaults;
  for (const Parameter& p : world_parameters()) {
    py::dict d;
    d["name"] = std::string(p.name);
    d["json_key"] = std::string(p.json_key);
    d["flag"] = p.flag.empty() ? std::string() : "--" + std::string(p.flag);
    d["unit"] = std::string(p.unit);
    d["allowed"] = p.allowed();
    d["default"] = p.format(p.get(defaults));
    d["help"] = std::string(p.help);
    py::list choices;
    for (const Choice& c : p.choices) choices.append(std::string(c.name));
    d["choices"] = choices;
    out.append(d);
  }
  return out;
}

// The parameter a keyword names: a WorldDef member name or a JSON key. Throws ValueError with
// the nearest name.
const Parameter& find_parameter(const std::string& key) {
  std::vector<std::string> names;
  for (const Parameter& p : world_parameters()) {
    if (p.name == key || p.json_key == key) return p;
    names.emplace_back(p.json_key);
  }
  throw py::value_error("unknown world parameter '" + key + "'; did you mean '" +
                        nearest_name(key, names) + "'? (cps.parameters() lists them)");
}

// A keyword's value as the command line would type it, parsed by the parameter (its checks and
// messages): a number (17 digits), True/False, a choice's name or three numbers.
ParameterValue parameter_value(const Parameter& p, const py::handle& value) {
  std::string text;
  if (py::isinstance<py::bool_>(value)) {
    text = value.cast<bool>() ? "true" : "false";
  } else if (py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value)) {
    text = decimal(value.cast<double>());
  } else if (py::isinstance<py::str>(value)) {
    text = value.cast<std::string>();
  } else if (py::isinstance<py::sequence>(value) && py::len(value) == 3) {
    for (const py::handle item : value) {
      if (!(py::isinstance<py::int_>(item) || py::isinstance<py::float_>(item)) ||
          py::isinstance<py::bool_>(item)) {
        throw py::value_error(std::string(p.json_key) + ": three numbers are needed");
      }
      text += (text.empty() ? "" : ",") + decimal(item.cast<double>());
    }
  } else {
    throw py::value_error(std::string(p.json_key) + ": a value of type " +
                          std::string(py::str(py::type::of(value).attr("__name__"))) +
                          " is not allowed; " + p.allowed());
  }
  try {
    return p.parse(text);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(std::string(p.json_key) + ": " + e.what());
  }
}

// The scene a name or a scene file's path gives. Raises OSError for a .json path that is not a
// readable file, ValueError for an unknown name or an invalid file.
const scenes::Scene& resolve_scene(const std::string& name) {
  if (name.size() > 5 && name.ends_with(".json")) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(name, ec)) {
      const std::string message = "scene file '" + name + "' does not exist or is not a regular file";
      PyErr_SetString(PyExc_FileNotFoundError, message.c_str());
      throw py::error_already_set();
    }
  }
  try {
    const std::vector<const scenes::Scene*> found = cli::select_scenes(name);
    if (found.size() != 1) {
      throw py::value_error("'" + name + "' names " + std::to_string(found.size()) +
                            " scenes; cps.Run takes one scene's name or a scene file's path");
    }
    return *found.front();
  } catch (const cli::UsageError& e) {
    throw py::value_error(e.what());
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

// A numpy array (rows, cols) of doubles, or (rows,) when cols is 0.
py::array_t<double> matrix(std::size_t rows, std::size_t cols) {
  if (cols == 0) return py::array_t<double>(static_cast<py::ssize_t>(rows));
  return py::array_t<double>({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)});
}

// `value` as a C-contiguous double array of shape (n, cols). Raises ValueError naming `key`.
py::array_t<double, py::array::c_style | py::array::forcecast> checked(const py::dict& state,
                                                                       const char* key,
                                                                       std::size_t n,
                                                                       std::size_t cols) {
  if (!state.contains(key)) throw py::value_error(std::string("set_state: '") + key + "' is missing");
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(state[key]);
  if (!a || a.ndim() != 2 || static_cast<std::size_t>(a.shape(0)) != n ||
      static_cast<std::size_t>(a.shape(1)) != cols) {
    throw py::value_error(std::string("set_state: '") + key + "' must be an array of shape (" +
                          std::to_string(n) + ", " + std::to_string(cols) + ") of numbers");
  }
  const double* d = a.data();
  for (std::size_t k = 0; k < n * cols; ++k) {
    if (!std::isfinite(d[k])) {
      throw py::value_error(std::string("set_state: '") + key + "' holds a value that is not finite (row " +
                            std::to_string(k / cols) + ")");
    }
  }
  return a;
}

// Runs a cps command line in this process (run_command) with argv ["cps", args...]. Its messages
// on std::cerr are kept and printed after it; exit 2 raises ValueError with them, exit 1
// RuntimeError; else the exit status (0, or 3 for a warning under --warnings-as-errors).
int command(const std::vector<std::string>& args) {
  if (args.empty()) throw py::value_error("cps.command: give the command and its arguments, e.g. ['list']");
  std::vector<std::string> words = {"cps"};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  std::ostringstream messages;
  int status = 0;
  {
    py::gil_scoped_release release;
    std::cout.flush();
    std::streambuf* old = std::cerr.rdbuf(messages.rdbuf());
    status = cli::run_command(static_cast<int>(words.size()), argv.data());
    std::cerr.rdbuf(old);
    std::cout.flush();
  }
  std::string text = messages.str();
  if (!text.empty()) std::cerr << text << std::flush;
  while (!text.empty() && text.back() == '\n') text.pop_back();
  if (status == 2) throw py::value_error(text);
  if (status == 1) throw std::runtime_error(text);
  return status;
}

// The command line of `cps COMMAND scene` with **options as flags: key k becomes --k with '_' as
// '-'; True alone, False and None left out; a (width, height) size as WxH; a list or tuple joined
// by commas; numbers with 17 digits.
int command_with_options(const std::string& name, const std::string& scene, const py::kwargs& options) {
  std::vector<std::string> args = {name, scene};
  for (const auto& [key, value] : options) {
    std::string flag = "--" + py::str(key).cast<std::string>();
    for (char& c : flag) c = c == '_' ? '-' : c;
    if (value.is_none()) continue;
    if (py::isinstance<py::bool_>(value)) {
      if (value.cast<bool>()) args.push_back(flag);
      continue;
    }
    const auto text = [](const py::handle& v) -> std::string {
      if (py::isinstance<py::float_>(v)) return decimal(v.cast<double>());
      return py::str(v).cast<std::string>();
    };
    std::string joined;
    if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
      const char* separator = flag == "--size" ? "x" : ",";
      for (const py::handle item : value) {
        if (!joined.empty()) joined += separator;
        joined += text(item);
      }
    } else {
      joined = text(value);
    }
    args.push_back(flag);
    args.push_back(joined);
  }
  return command(args);
}

/// A world built from a scene (cps.Run): see the docstrings below.
class PyRun {
 public:
  PyRun(const std::string& scene, const py::kwargs& params) : scene_(&resolve_scene(scene)) {
    for (const auto& [key, value] : params) {
      const Parameter& p = find_parameter(py::str(key));
      try {
        overrides_.set(p, parameter_value(p, value));
      } catch (const std::invalid_argument& e) {
        throw py::value_error(std::string(p.json_key) + ": " + e.what());
      }
    }
    try {
      run_ = std::make_unique<scenes::Run>(scenes::make_run(*scene_, overrides_));
    } catch (const std::invalid_argument& e) {
      throw py::value_error(e.what());
    }
    as_built_ = std::make_unique<World>(run_->world);
  }

  void step(long long n) {
    if (n < 0 || n > 100'000'000) {
      throw py::value_error("step: n = " + std::to_string(n) + " is not allowed; give 0 to 1e8 steps");
    }
    py::gil_scoped_release release;
    for (long long k = 0; k < n; ++k) run_->step();
  }

  void advance_to(double t) {
    const double now = run_->world.time();
    const double steps = (t - now) / run_->world.def().dt;
    if (!std::isfinite(t) || steps > 1e8) {
      throw py::value_error("advance_to: t = " + py::repr(py::float_(t)).cast<std::string>() +
                            " s is not allowed; give a finite time at most 1e8 steps ahead");
    }
    py::gil_scoped_release release;
    run_->advance_to(t);
  }

  double time() const { return run_->world.time(); }

  py::dict state() const {
    const auto& bodies = run_->world.bodies();
    const std::size_t n = bodies.size();
    auto x = matrix(n, 3), o = matrix(n, 4), v = matrix(n, 3), w = matrix(n, 3), m = matrix(n, 0);
    py::array_t<bool> fixed(static_cast<py::ssize_t>(n));
    auto X = x.mutable_unchecked<2>();
    auto O = o.mutable_unchecked<2>();
    auto V = v.mutable_unchecked<2>();
    auto W = w.mutable_unchecked<2>();
    auto M = m.mutable_unchecked<1>();
    auto S = fixed.mutable_unchecked<1>();
    for (std::size_t i = 0; i < n; ++i) {
      const Body& b = bodies[i];
      const Vec3 vel = b.velocity();
      const Vec3 ang = b.is_static() ? Vec3::Zero() : b.angular_velocity();
      const auto k = static_cast<py::ssize_t>(i);
      for (int a = 0; a < 3; ++a) {
        X(k, a) = b.x[a];
        V(k, a) = vel[a];
        W(k, a) = ang[a];
      }
      O(k, 0) = b.o.w();
      O(k, 1) = b.o.x();
      O(k, 2) = b.o.y();
      O(k, 3) = b.o.z();
      M(k) = b.mass;
      S(k) = b.is_static();
    }
    std::vector<std::string> names = scenes::body_names(*scene_);
    names.resize(n);
    py::dict d;
    d["positions"] = x;
    d["orientations"] = o;
    d["linear_velocities"] = v;
    d["angular_velocities"] = w;
    d["masses"] = m;
    d["static"] = fixed;
    d["names"] = names;
    d["time"] = run_->world.time();
    return d;
  }

  void set_state(const py::dict& state) {
    const std::size_t n = run_->world.bodies().size();
    const auto x = checked(state, "positions", n, 3);
    const auto o = checked(state, "orientations", n, 4);
    const auto v = checked(state, "linear_velocities", n, 3);
    const auto w = checked(state, "angular_velocities", n, 3);
    // Checked whole on a copy first, so that a bad row changes nothing.
    World next = run_->world;
    const double* X = x.data();
    const double* O = o.data();
    const double* V = v.data();
    const double* W = w.data();
    for (std::size_t i = 0; i < n; ++i) {
      try {
        next.set_body_state(static_cast<int>(i), Vec3(X[3 * i], X[3 * i + 1], X[3 * i + 2]),
                            Quat(O[4 * i], O[4 * i + 1], O[4 * i + 2], O[4 * i + 3]),
                            Vec3(V[3 * i], V[3 * i + 1], V[3 * i + 2]),
                            Vec3(W[3 * i], W[3 * i + 1], W[3 * i + 2]));
      } catch (const std::invalid_argument& e) {
        throw py::value_error("set_state: body " + std::to_string(i) + ": " + e.what());
      }
    }
    for (std::size_t i = 0; i < n; ++i) {
      const Body& b = next.bodies()[i];
      run_->world.set_body_state(static_cast<int>(i), b.x, b.o, b.velocity(),
                                 b.is_static() ? Vec3::Zero() : b.angular_velocity());
    }
  }

  py::object metrics() const {
    const World& world = run_->world;
    const StepCounters& c = world.counters();
    nlohmann::json j = {{"scene", scene_->name},
                        {"steps", c.steps},
                        {"simulated_s", world.time()},
                        {"metrics", run_->metrics->report()},
                        {"counters",
                         {{"pairs_tested", c.pairs_tested},
                          {"contacts", c.contacts},
                          {"rows", c.rows},
                          {"solves", c.solves}}},
                        {"state_hash", scenes::format_hash(scenes::state_hash(world))}};
    return to_python(j);
  }

  std::string state_hash() const { return scenes::format_hash(scenes::state_hash(run_->world)); }

  py::dict contacts() const {
    const World& world = run_->world;
    std::size_t k = 0;
    for (const Manifold& m : world.manifolds()) k += static_cast<std::size_t>(m.count);
    auto points = matrix(k, 3), normals = matrix(k, 3), depths = matrix(k, 0), lambda = matrix(k, 0);
    py::array_t<int> body_a(static_cast<py::ssize_t>(k)), body_b(static_cast<py::ssize_t>(k));
    auto P = points.mutable_unchecked<2>();
    auto N = normals.mutable_unchecked<2>();
    auto D = depths.mutable_unchecked<1>();
    auto L = lambda.mutable_unchecked<1>();
    auto A = body_a.mutable_unchecked<1>();
    auto B = body_b.mutable_unchecked<1>();
    // lambda of a point's contact row where the step's first rows are one a point (its
    // contact_forces' normal part), NaN where they are not.
    const std::vector<Vec3> forces = cli::contact_forces(world);
    py::ssize_t r = 0;
    for (const Manifold& m : world.manifolds()) {
      for (int i = 0; i < m.count; ++i, ++r) {
        const Contact& c = m.contacts[static_cast<std::size_t>(i)];
        for (int a = 0; a < 3; ++a) {
          P(r, a) = c.point[a];
          N(r, a) = c.normal[a];
        }
        D(r) = c.depth;
        L(r) = forces.empty() ? std::nan("") : world.lambda()[static_cast<std::size_t>(r)];
        A(r) = m.body_a;
        B(r) = m.body_b;
      }
    }
    py::dict d;
    d["points"] = points;
    d["normals"] = normals;
    d["depths"] = depths;
    d["lambda"] = lambda;
    d["body_a"] = body_a;
    d["body_b"] = body_b;
    return d;
  }

  py::array_t<std::uint8_t> render(const std::pair<int, int>& size, const std::string& camera,
                                   const std::string& backend, std::optional<double> seconds) {
    const auto [width, height] = size;
    if (width < 16 || width > 8192 || height < 16 || height > 8192) {
      throw py::value_error("render: size (" + std::to_string(width) + ", " + std::to_string(height) +
                            ") is not allowed; width and height must be in [16, 8192] pixels");
    }
    const std::optional<render::Backend> chosen = render::parse_backend(backend);
    if (!chosen) {
      throw py::value_error("render: backend '" + backend + "' is not allowed; give auto, osmesa or egl");
    }
    const double fit_seconds = seconds.value_or(scene_->default_seconds);
    if (!(fit_seconds >= 0.0 && fit_seconds / run_->world.def().dt <= 1e7)) {
      throw py::value_error("render: seconds must be >= 0 and at most 1e7 steps");
    }
    cli::View view;
    view.camera = camera;
    view.camera_given = camera != "preset";
    view = cli::scene_view(*scene_, view);
    cli::DrawStyle style;
    try {
      const World* worlds[] = {as_built_.get()};
      style = cli::resolve_style(*scene_, worlds, view,
                                 static_cast<float>(width) / static_cast<float>(height), fit_seconds);
    } catch (const cli::UsageError& e) {
      throw py::value_error(std::string("render: ") + e.what());
    }
    if (!renderer_ || renderer_->width() != width || renderer_->height() != height ||
        backend_ != backend) {
      renderer_.reset();
      try {
        renderer_ = std::make_unique<render::Renderer>(width, height, *chosen);
      } catch (const std::exception& e) {
        throw std::runtime_error(std::string("render: ") + e.what());
      }
      backend_ = backend;
    }
    const render::Image image = renderer_->draw(cli::draw_list(run_->world, style));
    py::array_t<std::uint8_t> out({static_cast<py::ssize_t>(image.height),
                                   static_cast<py::ssize_t>(image.width), py::ssize_t{3}});
    std::copy(image.pixels.begin(), image.pixels.end(), out.mutable_data());
    return out;
  }

  std::string repr() const {
    std::ostringstream s;
    s << "cps.Run('" << scenes::output_name(*scene_) << "', t = " << run_->world.time() << " s, "
      << run_->world.bodies().size() << " bodies)";
    return s.str();
  }

 private:
  const scenes::Scene* scene_;
  scenes::Overrides overrides_;
  std::unique_ptr<scenes::Run> run_;
  std::unique_ptr<World> as_built_;  // the world before its first step, for the cameras
  std::unique_ptr<render::Renderer> renderer_;
  std::string backend_;
};

}  // namespace
}  // namespace cps::python

PYBIND11_MODULE(cps, m) {
  using cps::python::PyRun;
  m.doc() = "cps: the constraint based rigid body solver of Tamis & Maggiore (2015), its scenes, "
            "steps, states and pictures as numpy arrays. SI units throughout.";
  // Any C++ error that is not already a Python one: a runtime failure (RuntimeError).
  m.def("scenes", &cps::python::scene_list,
        "The built-in scenes (what `cps list` prints): a list of dicts with name, group (paper, "
        "stress, benchmark, example), default_seconds (s) and summary. Scaled families "
        "(stack_N, pyramid_N, ...) and random_SEED are made on demand by cps.Run.");
  m.def("parameters", &cps::python::parameter_list,
        "The world parameter table: a list of dicts with name (a keyword of cps.Run), json_key "
        "(also a keyword), flag (the command's option), unit (SI), allowed, default (as text), "
        "help and choices.");
  m.def("command", &cps::python::command, py::arg("args"),
        "Runs a cps command line in this process, as the `cps` executable runs it: "
        "cps.command(['figure', 'stack', '--times', '0,1', '--out', 'figs/']). Its output and "
        "messages print as the command's do; files go where the command puts them, under its "
        "output rule (nothing foreign overwritten, nothing half written). Returns the exit status "
        "(0, or 3 for a warning under --warnings-as-errors). Raises ValueError for a usage error "
        "(exit 2, with the command's message), RuntimeError for a failure (exit 1).");
  m.def("render",
        [](const std::string& scene, const py::kwargs& options) {
          return cps::python::command_with_options("render", scene, options);
        },
        py::arg("scene"),
        "`cps render SCENE` with options as keywords (out='out', seconds=2, fps=1, "
        "size=(160, 120), camera='fit', compare='push', push='split', video='mp4', label=True): "
        "writes the frames (and video) under the command's output rule. Returns and raises as "
        "cps.command.");
  m.def("figure",
        [](const std::string& scene, const py::kwargs& options) {
          return cps::python::command_with_options("figure", scene, options);
        },
        py::arg("scene"),
        "`cps figure SCENE` with options as keywords (times=[0, 1, 2], size=(400, 225), "
        "out='figs/', compare='push', velocities=True): writes the figure and its sidecar under "
        "the command's output rule. Returns and raises as cps.command.");
  py::class_<PyRun>(m, "Run",
                    "A world built from a scene, ready to step.\n\n"
                    "Run(scene, **params): scene is a built-in name ('stack', 'pyramid_100', "
                    "'random_7') or a scene file's path ('cradle.json'); params set world "
                    "parameters by name or JSON key (push='split', warm_start=0.8, dt=1/120; "
                    "cps.parameters() lists them). Raises ValueError for an unknown scene, "
                    "parameter or value (the command's message), OSError for a scene file that "
                    "cannot be read.")
      .def(py::init<const std::string&, const py::kwargs&>(), py::arg("scene"))
      .def("step", &PyRun::step, py::arg("n") = 1,
           "Steps n times (n in [0, 1e8]) at the world's dt and feeds the metrics. Raises "
           "ValueError for n outside that range.")
      .def("advance_to", &PyRun::advance_to, py::arg("t"),
           "Steps until the time reaches t (s) within half a step (as `cps simulate --seconds t`). "
           "A time already passed steps nothing. Raises ValueError for a non-finite t or one "
           "more than 1e8 steps ahead.")
      .def_property_readonly("time", &PyRun::time, "Simulated time (s): steps taken times dt.")
      .def("state", &PyRun::state,
           "The bodies' state in world order (planes included), a dict of numpy arrays: "
           "positions (N, 3) m, orientations (N, 4) unit quaternions w, x, y, z (body to world), "
           "linear_velocities (N, 3) m/s, angular_velocities (N, 3) rad/s (world frame), masses "
           "(N,) kg (0 for a static body), static (N,) bool, names (N strings: a scene file's "
           "body names, '' where none) and time (s).")
      .def("set_state", &PyRun::set_state, py::arg("state"),
           "Replaces every body's position, orientation and velocities from a dict shaped as "
           "state() gives (positions (N, 3), orientations (N, 4), linear_velocities (N, 3), "
           "angular_velocities (N, 3); other keys are ignored). Masses, shapes and time stay. "
           "Raises ValueError naming the key and body for a missing key, a wrong shape, a value "
           "that is not finite, or one the engine refuses (an orientation off unit norm by more "
           "than 1e-9, a position beyond 1e9 m); then nothing changes.")
      .def("metrics", &PyRun::metrics,
           "What `cps simulate --json` gives for the run so far: scene, steps, simulated_s (s), "
           "metrics (the scene's own measures), counters and state_hash, as a dict.")
      .def("state_hash", &PyRun::state_hash,
           "The state hash (16 hex digits) `cps simulate` prints: xxHash of every body's "
           "position, orientation and momenta bits.")
      .def("contacts", &PyRun::contacts,
           "The contact points of the last step, a dict of numpy arrays (K points): points "
           "(K, 3) m, normals (K, 3) unit from body a to body b, depths (K,) m (negative: a gap), "
           "lambda (K,) N (the contact row's lambda of the step's first solve; NaN for a push "
           "method that keeps no rows), body_a and body_b (K,) body indices.")
      .def("render", &PyRun::render, py::arg("size") = std::pair<int, int>(640, 360),
           py::arg("camera") = "preset", py::arg("backend") = "auto",
           py::arg("seconds") = py::none(),
           "The world now as the command draws it, an (height, width, 3) uint8 RGB array. size: "
           "(width, height) px, each in [16, 8192]; camera: a --camera name (preset, auto, fit, "
           "fit:frame, track:BODY, ...; 'preset' takes the scene's default framing); backend: "
           "auto, osmesa or egl; seconds: the run length that fit and fit:frame frame (s; default "
           "the scene's duration). Raises ValueError for a bad size, camera or backend, "
           "RuntimeError when no GL context can be made.")
      .def("__repr__", &PyRun::repr);
}
