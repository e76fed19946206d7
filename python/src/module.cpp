// The compiled half of `import grainlab` (pybind11): configs validated by the program's own code
// (io/config.cpp), in-process runs through the same path as `grainlab run` (cli::runResolved), and
// a Simulation for step-level scripting with numpy views of the particle arrays. The Python half
// (grainlab/__init__.py) builds the user-facing functions on these.
#include <omp.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli/commands.hpp"
#include "cli/thread_count.hpp"
#include "core/contact_view.hpp"
#include "core/errors.hpp"
#include "io/config.hpp"
#include "io/input_file.hpp"
#include "io/install_paths.hpp"
#include "io/presets.hpp"
#include "lab/measurements.hpp"
#include "lab/protocols.hpp"

namespace py = pybind11;
namespace fs = std::filesystem;
using namespace grainlab;

namespace {

// The CLI's one line of an error (cli/main.cpp prints "grainlab: " and this).
std::string oneLine(const std::string& message) { return io::printable(message, 600); }

// ---------------------------------------------------------------------------------------------
// Configs

// A Python value of a config given as a dict, as the TOML value a file would hold.
toml::table tableFromDict(const py::dict& d, const std::string& prefix, int depth);

std::string describe(const py::handle& v) {
  return io::printable(py::str(py::repr(v)).cast<std::string>(), 80);
}

void checkDepth(int depth, const std::string& path) {
  if (depth > io::kMaxNesting)
    throw InputError(fmt::format("config error: {}: nested more than {} levels deep; allowed: at most {}",
                                 io::printable(path, 80), io::kMaxNesting, io::kMaxNesting));
}

void appendValue(toml::array& array, const py::handle& v, const std::string& path, int depth);

// Converts v and hands it to sink (which inserts it into a table or an array).
template <class Sink>
void insertValue(Sink&& sink, const py::handle& v, const std::string& path, int depth) {
  checkDepth(depth, path);
  if (py::isinstance<py::bool_>(v)) {
    sink(toml::value<bool>(v.cast<bool>()));
  } else if (py::isinstance<py::int_>(v)) {
    try {
      sink(toml::value<std::int64_t>(v.cast<std::int64_t>()));
    } catch (const py::cast_error&) {
      throw InputError(fmt::format("config error: {} = {}: out of the range of a TOML integer; allowed: "
                                   "-2^63 .. 2^63-1", io::printable(path, 80), describe(v)));
    }
  } else if (py::isinstance<py::float_>(v)) {
    sink(toml::value<double>(v.cast<double>()));
  } else if (py::isinstance<py::str>(v)) {
    sink(toml::value<std::string>(v.cast<std::string>()));
  } else if (py::isinstance<py::dict>(v)) {
    sink(tableFromDict(v.cast<py::dict>(), path, depth + 1));
  } else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    toml::array array;
    std::size_t k = 0;
    for (const py::handle item : v) appendValue(array, item, fmt::format("{}[{}]", path, k++), depth + 1);
    sink(std::move(array));
  } else {
    throw InputError(fmt::format("config error: {} = {}: a Python {} is not a config value; allowed: bool, int, "
                                 "float, str, list, dict",
                                 io::printable(path, 80), describe(v),
                                 py::str(py::type::of(v).attr("__name__")).cast<std::string>()));
  }
}

void appendValue(toml::array& array, const py::handle& v, const std::string& path, int depth) {
  insertValue([&](auto&& x) { array.push_back(std::forward<decltype(x)>(x)); }, v, path, depth);
}

toml::table tableFromDict(const py::dict& d, const std::string& prefix, int depth) {
  checkDepth(depth, prefix.empty() ? "config" : prefix);
  toml::table table;
  for (const auto& [k, v] : d) {
    if (!py::isinstance<py::str>(k))
      throw InputError(fmt::format("config error: {}key {}: not a string; allowed: string keys",
                                   prefix.empty() ? "" : prefix + ": ", describe(k)));
    const std::string key = k.cast<std::string>();
    const std::string path = prefix.empty() ? key : prefix + "." + key;
    insertValue([&](auto&& x) { table.insert_or_assign(key, std::forward<decltype(x)>(x)); }, v, path, depth);
  }
  return table;
}

// A validated config: the table (source plus overrides) and what it resolves to.
struct Config {
  std::string source;   // "preset:NAME", a file path, or "<dict>"
  std::string baseDir;  // relative file names of the config are resolved against it
  std::vector<std::string> overrides;
  toml::table table;    // after the overrides
  lab::RunConfig resolved;

  // The table with --out / --threads applied, validated again (as the CLI's resolveConfig does).
  lab::RunConfig withRunOptions(const std::string& out, int threads) const {
    toml::table t = table;
    if (!out.empty()) io::setOutputDir(t, out);
    if (threads > 0) io::applyOverride(t, fmt::format("solver.threads={}", threads));
    return io::parseConfig(t, baseDir);
  }
};

std::shared_ptr<Config> loadConfig(const py::object& source, const std::vector<std::string>& overrides) {
  auto c = std::make_shared<Config>();
  if (py::isinstance<py::dict>(source)) {
    c->source = "<dict>";
    c->baseDir = fs::current_path().string();
    c->table = tableFromDict(source.cast<py::dict>(), "", 1);
  } else if (py::isinstance<py::str>(source) || py::isinstance(source, py::module_::import("os").attr("PathLike"))) {
    c->source = py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>();
    c->table = io::loadConfigTable(c->source);
    c->baseDir = io::configBaseDir(c->source);
  } else {
    throw InputError(fmt::format("config error: config source {}: allowed: a preset name, \"preset:NAME\", a TOML "
                                 "file path or a dict", describe(source)));
  }
  c->overrides = overrides;
  for (const auto& s : overrides) io::applyOverride(c->table, s);
  c->resolved = io::parseConfig(c->table, c->baseDir);
  return c;
}

// ---------------------------------------------------------------------------------------------
// Runs: the Python progress callback and Ctrl-C between chunks of steps.

// The progress observer of a run, called by the engine's thread with the GIL released: it takes
// the GIL, lets Python handle pending signals (Ctrl-C raises KeyboardInterrupt there) and calls the
// user's callback. A Python exception from either is kept and the run stopped between steps by
// RunInterrupted; the caller re-raises the kept exception once the run has unwound.
class PythonObserver {
 public:
  explicit PythonObserver(py::object callback) : callback_(std::move(callback)) {}

  lab::ProgressFn function() {
    return [this](const std::string& phase, double fraction, long steps) {
      py::gil_scoped_acquire gil;
      try {
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        if (!callback_.is_none()) callback_(phase, fraction, steps);
      } catch (py::error_already_set& e) {
        pending_.emplace(std::move(e));
        throw RunInterrupted(fmt::format("interrupted: {}", io::printable(pending_->what(), 200)));
      }
    };
  }
  bool stopped() const { return pending_.has_value(); }
  // Re-raises the Python exception that stopped the run (call with the GIL held).
  [[noreturn]] void reraise() {
    py::error_already_set e = std::move(*pending_);
    pending_.reset();
    throw e;
  }

 private:
  py::object callback_;
  std::optional<py::error_already_set> pending_;
};

// Runs a config in-process through the program's own `run` (cli::runResolved): the results folder
// is the one `grainlab run` would write. Returns the folder's absolute path.
std::string runConfig(const Config& c, const std::string& out, int threads, bool quiet, py::object progress) {
  const lab::RunConfig config = c.withRunOptions(out, threads);
  cli::RunOptions opt;
  opt.config = c.source;
  opt.quiet = quiet;
  PythonObserver observer(std::move(progress));
  {
    py::gil_scoped_release release;
    try {
      cli::runResolved(config, opt, observer.function());
    } catch (const SimulationError&) {
      // Stopped by the observer: RunInterrupted, or for a re-run into earlier results the
      // SimulationError that says they were left as they were.
      if (!observer.stopped()) throw;
    }
  }
  if (observer.stopped()) observer.reraise();
  return fs::absolute(config.output.dir).lexically_normal().string();
}

// ---------------------------------------------------------------------------------------------
// Step-level scripting

// The prepared sample of a config and the engine that steps it: the Laboratory's own preparation,
// then whatever the script does with the boundary between calls of step().
class PySimulation {
 public:
  PySimulation(std::shared_ptr<Config> config, int threads, py::object progress)
      : config_(std::move(config)),
        threads_(threads > 0 ? threads : config_->resolved.solver.threads),
        observer_(std::make_unique<PythonObserver>(std::move(progress))) {
    const lab::RunConfig& rc = config_->resolved;
    lab_ = std::make_unique<lab::Laboratory>(rc, observer_->function());
    warnIfForked();
    {
      py::gil_scoped_release release;
      cli::setOpenMPThreads(threads_);
      try {
        std::optional<Simulation> packed = cli::loadInputFiles(rc);
        prep_ = packed ? lab_->adoptPacking(std::move(*packed)) : lab_->prepare();
      } catch (const RunInterrupted&) {
        if (!observer_->stopped()) throw;
      }
    }
    if (observer_->stopped()) observer_->reraise();
    resetReference();
  }

  // The engine, for every method and property: refused while step() runs in another Python thread
  // (step releases the GIL, so another thread could otherwise change or read the arrays mid-step:
  // issue 28 saw "double free or corruption" and lost steps). The flag is set and tested with the
  // GIL held, so the test and the set cannot interleave.
  Simulation& sim() {
    checkIdle();
    return lab_->simulation();
  }
  const Simulation& sim() const {
    checkIdle();
    return lab_->simulation();
  }
  void checkIdle() const {
    if (busy_.load(std::memory_order_acquire))
      throw std::runtime_error(
          "this grainlab.Simulation is stepping in another thread: one Simulation is driven by one thread at a time "
          "(wait for step() to return, or give each thread its own Simulation)");
  }

  // Steps n times with the GIL released; every kChunk steps takes the GIL to let Python handle
  // Ctrl-C (KeyboardInterrupt, the state then being that after a whole step).
  void step(long n) {
    if (n < 0) throw py::value_error(fmt::format("step: n = {}; allowed: n >= 0", n));
    checkIdle();
    warnIfForked();
    struct Busy {
      std::atomic<bool>& flag;
      explicit Busy(std::atomic<bool>& f) : flag(f) { flag.store(true, std::memory_order_release); }
      ~Busy() { flag.store(false, std::memory_order_release); }
    } busy(busy_);
    Simulation& engine = lab_->simulation();
    constexpr long kChunk = 1000;
    long done = 0;
    while (done < n) {
      const long chunk = std::min(kChunk, n - done);
      {
        py::gil_scoped_release release;
        cli::setOpenMPThreads(threads_);
        for (long k = 0; k < chunk; ++k) engine.step();
      }
      done += chunk;
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
  }

  // A process forked after OpenMP teams ran steps on one thread (cli/thread_count.hpp): said once.
  void warnIfForked() {
    if (warnedFork_ || threads_ <= 1 || !cli::forkedAfterOpenMPTeams()) return;
    warnedFork_ = true;
    const std::string text = cli::forkedThreadsWarning(threads_);
    if (PyErr_WarnEx(PyExc_RuntimeWarning, text.c_str(), 1) != 0) throw py::error_already_set();
  }

  // The state the strains are measured from: the current one (lab/boundary_control.hpp).
  void resetReference() { boundary().setReference(); }
  // Engineering strains of the sample's lengths since the reference, compression positive.
  Eigen::Vector3d strain() const { return boundary().strain(); }
  double volumetricStrain() const { return boundary().volumetricStrain(); }
  lab::BoundaryControl& boundary() const { return lab_->boundary(); }

  static void checkAxis(int axis) {
    if (axis < 0 || axis > 2) throw py::value_error(fmt::format("axis = {}; allowed: 0 (x), 1 (y), 2 (z)", axis));
  }
  static void checkFinite(double v, const char* what) {
    if (!std::isfinite(v)) throw py::value_error(fmt::format("{} = {}; allowed: a finite number", what, v));
  }

  // Stress control of one axis: both walls of the axis, or only the lower (side 0) or upper (side 1)
  // one, or the cell's diagonal component, servo to `stress` [Pa], compression positive.
  void setStress(int axis, double stress, std::optional<int> side) {
    checkAxis(axis);
    checkFinite(stress, "stress");
    if (stress < 0.0) throw py::value_error(fmt::format("stress = {}; allowed: >= 0 (compression positive)", stress));
    if (side && *side != 0 && *side != 1)
      throw py::value_error(fmt::format("side = {}; allowed: 0 (lower wall), 1 (upper wall) or None (both)", *side));
    if (side && boundary().periodic()) throw py::value_error("side: a periodic cell has no walls; allowed: None");
    if (side) boundary().holdFaceStress(axis, *side, stress);
    else boundary().holdStress(axis, stress);
  }
  // Simple shear of the cell: L_xz = rate (dx/dt = rate z) [1/s]; 0 stops it.
  void setShearRate(double rate) {
    checkFinite(rate, "rate");
    if (!boundary().periodic())
      throw py::value_error("set_shear_rate: only a periodic cell shears (test.boundary = \"periodic\")");
    boundary().holdShape();
    boundary().imposeShearRate(rate);
  }
  // Strain control of one axis at an engineering rate of the reference length [1/s], compression
  // positive: the walls move towards each other at rate L0/2 each (as the CLI's platens), or the
  // cell's H_ii changes at -rate H0_ii. A strained cell keeps its principal axes (no shear servo),
  // as the CLI's shearing tests do; hold_isotropic() gives the shear stresses back to their servo.
  void setStrainRate(int axis, double rate) {
    checkAxis(axis);
    checkFinite(rate, "rate");
    boundary().holdShape();
    boundary().imposeStrainRate(axis, rate);
  }
  // Constant volume taken up by this axis (an undrained test on a dry sample): the volume at the
  // call is kept.
  void setConstantVolume(int axis) {
    checkAxis(axis);
    boundary().holdShape();
    boundary().constantVolume(axis);
  }

  double d50() const { return prep_.grading.d50; }

  std::shared_ptr<Config> config_;
  int threads_;
  std::unique_ptr<PythonObserver> observer_;  // the laboratory's progress reports (preparation)
  std::unique_ptr<lab::Laboratory> lab_;
  lab::PreparationResult prep_;
  mutable std::atomic<bool> busy_{false};
  bool warnedFork_ = false;
};

py::array vec3View(std::vector<Vec3>& v, py::handle owner, bool writeable) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  py::array a(py::dtype::of<double>(), {static_cast<py::ssize_t>(v.size()), py::ssize_t{3}},
              {static_cast<py::ssize_t>(sizeof(Vec3)), static_cast<py::ssize_t>(sizeof(double))},
              v.empty() ? nullptr : v.front().data(), owner);
  if (!writeable) py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

template <class T>
py::array scalarView(std::vector<T>& v, py::handle owner, bool writeable) {
  py::array a(py::dtype::of<T>(), {static_cast<py::ssize_t>(v.size())}, {static_cast<py::ssize_t>(sizeof(T))},
              v.data(), owner);
  if (!writeable) py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::array quatView(std::vector<Quat>& v, py::handle owner) {
  static_assert(sizeof(Quat) == 4 * sizeof(double));  // Eigen stores (x, y, z, w)
  py::array a(py::dtype::of<double>(), {static_cast<py::ssize_t>(v.size()), py::ssize_t{4}},
              {static_cast<py::ssize_t>(sizeof(Quat)), static_cast<py::ssize_t>(sizeof(double))},
              v.empty() ? nullptr : v.front().coeffs().data(), owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::array_t<double> matrix(const Mat3& m) {
  py::array_t<double> a({3, 3});
  auto r = a.mutable_unchecked<2>();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = m(i, j);
  return a;
}
py::array_t<double> vector3(const Vec3& v) {
  py::array_t<double> a(3);
  auto r = a.mutable_unchecked<1>();
  for (int i = 0; i < 3; ++i) r(i) = v[i];
  return a;
}

// A copy of the touching contacts (ContactView of every pair kind, in the engine's order).
py::dict contacts(const Simulation& sim) {
  std::vector<ContactView> list;
  forEachTouchingContact(sim, [&](const ContactView& v) { list.push_back(v); });
  const auto n = static_cast<py::ssize_t>(list.size());
  py::array_t<std::uint32_t> a(n), b(n);
  py::array_t<bool> wall(n);
  py::array_t<double> force({n, py::ssize_t{3}}), fn({n, py::ssize_t{3}}), ft({n, py::ssize_t{3}}),
      normal({n, py::ssize_t{3}}), branch({n, py::ssize_t{3}}), overlap(n);
  auto ra = a.mutable_unchecked<1>();
  auto rb = b.mutable_unchecked<1>();
  auto rw = wall.mutable_unchecked<1>();
  auto rf = force.mutable_unchecked<2>();
  auto rn = fn.mutable_unchecked<2>();
  auto rt = ft.mutable_unchecked<2>();
  auto rnn = normal.mutable_unchecked<2>();
  auto rbr = branch.mutable_unchecked<2>();
  auto ro = overlap.mutable_unchecked<1>();
  for (py::ssize_t c = 0; c < n; ++c) {
    const ContactView& v = list[c];
    ra(c) = v.a;
    rb(c) = v.b;
    rw(c) = v.wall;
    // The normal part along the contact normal, the tangential part the rest ([W] eq. 1-2 split).
    const Vec3 normalPart = v.force.dot(v.normal) * v.normal;
    const Vec3 tangentialPart = v.force - normalPart;
    for (int k = 0; k < 3; ++k) {
      rf(c, k) = v.force[k];
      rn(c, k) = normalPart[k];
      rt(c, k) = tangentialPart[k];
      rnn(c, k) = v.normal[k];
      rbr(c, k) = v.branch[k];
    }
    ro(c) = v.overlap;
  }
  py::dict d;
  d["a"] = a;
  d["b"] = b;
  d["wall"] = wall;
  d["force"] = force;
  d["normal_force"] = fn;
  d["tangential_force"] = ft;
  d["normal"] = normal;
  d["branch"] = branch;
  d["overlap"] = overlap;
  return d;
}

}  // namespace

PYBIND11_MODULE(_grainlab, m) {
  m.doc() = "grainlab's compiled core (use the grainlab package)";
  cli::applySimdEnvironment();  // GRAINLAB_SIMD, as for the program: a bad value fails the import

  static py::exception<InputError> configError(m, "ConfigError", PyExc_ValueError);
  static py::exception<SimulationError> simulationError(m, "SimulationError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(configError.ptr(), oneLine(e.what()).c_str());
    } catch (const SimulationError& e) {
      PyErr_SetString(simulationError.ptr(), oneLine(std::string("run failed: ") + e.what()).c_str());
    } catch (const io::FileError& e) {
      PyErr_SetString(PyExc_RuntimeError, oneLine(e.what()).c_str());
    } catch (const fs::filesystem_error& e) {
      PyErr_SetString(PyExc_RuntimeError,
                      oneLine(fmt::format("{} {}: {}", e.what(), io::quotedPath(e.path1()), e.code().message())).c_str());
    }
  });

  m.def("set_data_dir", [](const std::string& dir) { io::setDataDir(dir); },
        "share/grainlab of this installation (plot scripts, presets' data files)");
  m.def("version", [] { return std::string(GRAINLAB_VERSION); });
  m.def("presets", [] {
    std::vector<std::pair<std::string, std::string>> out;
    for (const auto& p : io::presets()) out.emplace_back(p.name, p.description);
    return out;
  });
  m.def("is_preset", [](const std::string& name) { return io::findPreset(name) != nullptr; });

  py::class_<Config, std::shared_ptr<Config>>(m, "Config")
      .def_readonly("source", &Config::source)
      .def_readonly("overrides", &Config::overrides)
      .def_readonly("base_dir", &Config::baseDir)
      .def("toml", [](const Config& c) { return io::toTomlString(c.table); }, "the config as given (with overrides)")
      .def("resolved_toml", [](const Config& c) { return io::toTomlString(io::resolvedTable(c.resolved)); },
           "every key with its default filled in (as `grainlab check` prints it)")
      .def_property_readonly("output_dir", [](const Config& c) { return c.resolved.output.dir; })
      .def_property_readonly("threads", [](const Config& c) { return c.resolved.solver.threads; });

  m.def("load_config", &loadConfig, py::arg("source"), py::arg("overrides"));
  m.def("run", &runConfig, py::arg("config"), py::arg("out"), py::arg("threads"), py::arg("quiet"),
        py::arg("progress"));

  py::class_<PySimulation>(m, "Simulation", py::dynamic_attr())
      .def(py::init<std::shared_ptr<Config>, int, py::object>(), py::arg("config"), py::arg("threads") = 0,
           py::arg("progress") = py::none())
      .def("step", &PySimulation::step, py::arg("n") = 1)
      .def("reset_reference", &PySimulation::resetReference)
      .def("set_stress", &PySimulation::setStress, py::arg("axis"), py::arg("stress"), py::arg("side") = py::none())
      .def("set_shear_rate", &PySimulation::setShearRate, py::arg("rate"))
      .def("set_strain_rate", &PySimulation::setStrainRate, py::arg("axis"), py::arg("rate"))
      .def("set_constant_volume", &PySimulation::setConstantVolume, py::arg("axis"),
           "Hold the volume constant through this axis's length (undrained shearing of a dry sample)")
      .def("hold_isotropic", [](PySimulation& s, double p) {
            PySimulation::checkFinite(p, "p");
            if (p <= 0.0) throw py::value_error(fmt::format("p = {}; allowed: > 0", p));
            lab::holdIsotropicStress(s.sim(), p);
          }, py::arg("p"))
      .def_property_readonly("positions", [](py::object self) {
            return vec3View(self.cast<PySimulation&>().sim().particles.position, self, true); })
      .def_property_readonly("velocities", [](py::object self) {
            return vec3View(self.cast<PySimulation&>().sim().particles.velocity, self, true); })
      .def_property_readonly("angular_velocities", [](py::object self) {
            return vec3View(self.cast<PySimulation&>().sim().particles.angularVelocity, self, false); })
      .def_property_readonly("forces", [](py::object self) {
            return vec3View(self.cast<PySimulation&>().sim().particles.force, self, false); })
      .def_property_readonly("semi_axes", [](py::object self) {
            return vec3View(self.cast<PySimulation&>().sim().particles.semiAxes, self, false); })
      .def_property_readonly("orientations", [](py::object self) {
            return quatView(self.cast<PySimulation&>().sim().particles.orientation, self); })
      .def_property_readonly("radii", [](py::object self) {
            return scalarView(self.cast<PySimulation&>().sim().particles.radius, self, false); })
      .def_property_readonly("masses", [](py::object self) {
            return scalarView(self.cast<PySimulation&>().sim().particles.mass, self, false); })
      .def_property_readonly("ids", [](py::object self) {
            return scalarView(self.cast<PySimulation&>().sim().particles.id, self, false); })
      .def("contacts", [](const PySimulation& s) { return contacts(s.sim()); })
      .def_property_readonly("n_particles", [](const PySimulation& s) { return s.sim().particles.size(); })
      .def_property_readonly("periodic", [](const PySimulation& s) { return s.sim().boundary == Boundary::Periodic; })
      .def_property_readonly("step_count", [](const PySimulation& s) { return s.sim().stepCount; })
      .def_property_readonly("time", [](const PySimulation& s) { return s.sim().time; })
      .def_property_readonly("dt", [](const PySimulation& s) { return s.sim().dt; })
      .def_property_readonly("d50", &PySimulation::d50)
      .def_property_readonly("density", [](const PySimulation& s) { return s.config_->resolved.sample.density; })
      .def_property_readonly("preparation_steps", [](const PySimulation& s) { return s.prep_.steps; })
      .def_property_readonly("boundary_stress", [](const PySimulation& s) { return vector3(lab::boundaryStress(s.sim())); })
      .def_property_readonly("wall_stresses", [](const PySimulation& s) {
            const auto w = lab::singleWallStresses(s.sim());
            return std::vector<double>(w.begin(), w.end()); })
      .def_property_readonly("contact_stress", [](const PySimulation& s) { return matrix(lab::contactStress(s.sim())); })
      .def_property_readonly("void_ratio", [](const PySimulation& s) { return lab::voidRatio(s.sim()); })
      .def_property_readonly("coordination", [](const PySimulation& s) { return lab::coordinationNumber(s.sim()); })
      .def_property_readonly("unbalanced", [](const PySimulation& s) { return lab::unbalancedForceRatio(s.sim()); })
      .def_property_readonly("wall_positions", [](const PySimulation& s) -> py::object {
            // xlo, xhi, ylo, yhi, zlo, zhi [m]: the planes of the six walls (None for a cell).
            if (s.sim().boundary == Boundary::Periodic) return py::none();
            std::array<double, 6> planes{};
            for (const Wall& w : s.sim().box.walls) planes[2 * w.axis + w.side] = w.position;
            return py::cast(planes);
          })
      .def_property_readonly("lengths", [](const PySimulation& s) { return vector3(lab::sampleLengths(s.sim())); })
      .def_property_readonly("volume", [](const PySimulation& s) { return s.sim().volume(); })
      .def_property_readonly("strain", [](const PySimulation& s) { return vector3(s.strain()); })
      .def_property_readonly("volumetric_strain", &PySimulation::volumetricStrain)
      .def_property_readonly("cell", [](const PySimulation& s) -> py::object {
            if (s.sim().boundary != Boundary::Periodic) return py::none();
            return matrix(s.sim().cell.h); })
      .def_property_readonly("energy", [](const PySimulation& s) {
            py::dict d;
            d["kinetic"] = lab::kineticEnergy(s.sim());
            d["elastic"] = lab::elasticEnergy(s.sim());
            d["slip"] = s.sim().energy.slip;
            d["rolling"] = s.sim().energy.rolling;
            d["damping"] = s.sim().energy.damping;
            d["boundary_work"] = s.sim().energy.boundaryWork;
            d["gravity_work"] = s.sim().energy.gravityWork;
            return d; });
}
