// SPDX-License-Identifier: Apache-2.0
// `import sweepers`: the engine for Python notebooks (docs/python.md). The work is done by
// python/shape.h and the io layer; this file turns Python's values into the engine's and
// back, releases the GIL around engine work, turns Ctrl-C (SIGINT) into the engine's
// cancellation, and the engine's errors into Python's exceptions.
#include <atomic>
#include <csignal>
#include <filesystem>
#include <optional>
#include <string>

#include <dlfcn.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "core/install_paths.h"
#include "core/limits.h"
#include "io/isolated_read.h"
#include "io/mesh_file.h"
#include "io/start_grid.h"
#include "io/stroke_script.h"
#include "io/study_files.h"
#include "io/study_plan.h"
#include "io/vdb_file.h"
#include "python/shape.h"
#include "vdb/parallel.h"

namespace py = pybind11;
using namespace sweepers;
using sweepers::python::Session;
using sweepers::python::Shape;

namespace {

// --- Ctrl-C ------------------------------------------------------------------------------

std::atomic<FlagInterrupter*> gInterrupted{nullptr};
extern "C" void onInterrupt(int) {
    if (FlagInterrupter* f = gInterrupted.load()) f->interrupt();
}

// While engine work runs (without the GIL, so Python's own handler would not run until it
// ends), SIGINT stops it through the engine's interrupter. Python only handles signals on
// its main thread, so only work started there is given the handler.
class InterruptScope {
  public:
    InterruptScope() {
        const py::module_ threading = py::module_::import("threading");
        if (!threading.attr("current_thread")().is(threading.attr("main_thread")())) return;
        struct sigaction action = {};
        action.sa_handler = onInterrupt;
        sigemptyset(&action.sa_mask);
        installed_ = ::sigaction(SIGINT, &action, &previous_) == 0;
        if (installed_) gInterrupted.store(&flag);
    }
    ~InterruptScope() {
        if (!installed_) return; // (another thread's: the main thread's work keeps its own)
        ::sigaction(SIGINT, &previous_, nullptr);
        gInterrupted.store(nullptr);
    }
    InterruptScope(const InterruptScope&) = delete;
    InterruptScope& operator=(const InterruptScope&) = delete;
    FlagInterrupter flag;

  private:
    struct sigaction previous_ = {};
    bool installed_ = false;
};

// --- progress ----------------------------------------------------------------------------

// A progress argument: None, a callable taking (done, total), or True for a tqdm bar when
// tqdm is installed. An exception raised by the callable stops the work and is raised.
class ProgressCall {
  public:
    ProgressCall(const py::object& progress, const std::string& what, FlagInterrupter* stop)
        : stop_(stop) {
        if (progress.is_none() || (py::isinstance<py::bool_>(progress) && !progress.cast<bool>()))
            return;
        if (py::isinstance<py::bool_>(progress)) {
            try {
                bar_ = py::module_::import("tqdm.auto")
                           .attr("tqdm")(py::arg("desc") = what, py::arg("unit") = "step");
            } catch (const py::error_already_set&) {
                return; // no tqdm: no bar
            }
            return;
        }
        if (!PyCallable_Check(progress.ptr()))
            throw py::type_error("progress: a callable (done, total), True or None");
        callback_ = progress;
    }
    ~ProgressCall() {
        if (bar_) {
            try {
                bar_.attr("close")();
            } catch (const py::error_already_set&) {
            }
        }
    }
    ProgressCall(const ProgressCall&) = delete;
    ProgressCall& operator=(const ProgressCall&) = delete;

    // The engine's callback; called without the GIL.
    Progress progress() {
        if (!callback_ && !bar_) return {};
        return [this](std::size_t done, std::size_t total) {
            py::gil_scoped_acquire gil;
            try {
                if (callback_) {
                    callback_(done, total);
                } else {
                    bar_.attr("total") = total;
                    bar_.attr("n") = done;
                    bar_.attr("refresh")();
                }
            } catch (py::error_already_set& e) {
                if (!error_) error_.emplace(std::move(e));
                stop_->interrupt();
            }
        };
    }
    // Raises the callback's exception, if it raised one.
    void raiseCallbackError() {
        if (error_) {
            py::error_already_set e = std::move(*error_);
            error_.reset();
            throw e;
        }
    }

  private:
    FlagInterrupter* stop_;
    py::object callback_, bar_;
    std::optional<py::error_already_set> error_;
};

// Runs engine work without the GIL, stoppable by Ctrl-C, with progress.
template <typename Work>
auto runEngine(const py::object& progress, const std::string& what, const Work& work) {
    InterruptScope scope;
    ProgressCall call(progress, what, &scope.flag);
    const Progress report = call.progress();
    try {
        auto result = [&] {
            py::gil_scoped_release release;
            return work(&scope.flag, report);
        }();
        // The callback raised on its last call, after the engine's last poll: the call fails
        // all the same (what it made is dropped).
        call.raiseCallbackError();
        return result;
    } catch (const Cancelled&) {
        call.raiseCallbackError();
        throw;
    }
}

// Runs `read(session)` without the GIL once no other thread is using the session. A caller
// waits for the session without the GIL: the one using it may need the GIL for its progress
// callback.
template <typename Read> auto withSession(const Session& session, const Read& read) {
    py::gil_scoped_release release;
    const Session::Turn turn(session);
    return read(session);
}

// --- values ------------------------------------------------------------------------------

// A value as JSON text; ValueError for a number JSON cannot hold (NaN, infinity), which
// json.dumps would write as a word no JSON reader takes.
std::string textOf(const py::handle& value, const std::string& what) {
    try {
        return py::module_::import("json")
            .attr("dumps")(value, py::arg("allow_nan") = false)
            .cast<std::string>();
    } catch (py::error_already_set& e) {
        if (!e.matches(PyExc_ValueError)) throw;
        throw py::value_error(what + " holds a number that is not finite (NaN or infinity)");
    }
}

// The name of a value's type, for messages.
std::string typeName(const py::handle& value) {
    return py::str(py::type::of(value).attr("__name__")).cast<std::string>();
}

// A number given to a parameter: TypeError naming the parameter for anything else (a bool
// is not a number here).
double numberFrom(const py::handle& value, const std::string& what) {
    if (py::isinstance<py::bool_>(value) ||
        !(py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)))
        throw py::type_error(what + ": a number, not " + typeName(value));
    return value.cast<double>();
}

// A string given to a parameter: TypeError naming the parameter for anything else.
std::string stringFrom(const py::handle& value, const std::string& what) {
    if (!py::isinstance<py::str>(value))
        throw py::type_error(what + ": a string, not " + typeName(value));
    return value.cast<std::string>();
}

py::object fromJson(const std::string& text) {
    return py::module_::import("json").attr("loads")(text);
}

bool isPath(const py::handle& value) {
    return py::isinstance(value, py::module_::import("os").attr("PathLike"));
}

std::string pathOf(const py::handle& value) {
    return py::str(py::module_::import("os").attr("fspath")(value)).cast<std::string>();
}

// A script given as a path, a JSON string or a dict, and the directory its files are
// relative to.
struct GivenScript {
    StrokeScript script;
    std::string baseDir;
};
GivenScript scriptFrom(const py::handle& value) {
    const std::string here = std::filesystem::current_path().string();
    if (py::isinstance<py::dict>(value))
        return {loadStrokeScript(textOf(value, "the script (a dict)"), "the script (a dict)", here),
                here};
    if (!py::isinstance<py::str>(value) && !isPath(value))
        throw py::type_error("script: a path, a JSON string or a dict, not " +
                             py::str(py::type::of(value)).cast<std::string>());
    const std::string text = pathOf(value);
    const std::size_t first = text.find_first_not_of(" \t\r\n");
    if (py::isinstance<py::str>(value) && first != std::string::npos && text[first] == '{')
        return {loadStrokeScript(text, "the script (a JSON string)", here), here};
    try {
        return {readStrokeScript(text), directoryOf(text)};
    } catch (const ScriptError& e) {
        // The CLI's message, as an OSError when the file cannot be read at all.
        std::error_code ec;
        if (!std::filesystem::is_regular_file(text, ec)) throw FileError(e.what());
        throw;
    }
}

double voxelSizeFrom(const py::object& value) {
    if (value.is_none()) return 0.0;
    const double h = numberFrom(value, "voxel_size");
    if (!(h > 0.0 && std::isfinite(h)))
        throw std::invalid_argument("voxel_size must be a positive number, not " +
                                    py::repr(value).cast<std::string>());
    return h;
}

// numpy, which makes every array the module takes or hands over: where it is missing, said
// in the user's words with the Debian package that brings it (not a bare ModuleNotFoundError
// from deep inside pybind11).
void requireNumpy(const char* what) {
    try {
        py::module_::import("numpy");
    } catch (const py::error_already_set&) {
        throw py::import_error(std::string(what) +
                               ": numpy is not installed (Debian: python3-numpy, for "
                               "/usr/bin/python3)");
    }
}

using Points = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::vector<Eigen::Vector3d> pointsOf(const py::object& given, const char* what) {
    requireNumpy(what);
    const Points points = Points::ensure(given);
    if (!points || points.ndim() != 2 || points.shape(1) != 3)
        throw std::invalid_argument("points: an n x 3 array");
    std::vector<Eigen::Vector3d> p(std::size_t(points.shape(0)));
    const auto in = points.unchecked<2>();
    for (py::ssize_t i = 0; i < points.shape(0); ++i)
        p[std::size_t(i)] = {in(i, 0), in(i, 1), in(i, 2)};
    return p;
}

py::array_t<double> arrayOf(const std::vector<double>& values) {
    requireNumpy("arrays");
    py::array_t<double> out(py::ssize_t(values.size()));
    std::copy(values.begin(), values.end(), out.mutable_data());
    return out;
}

py::dict topologyOf(const LevelSetMeasures& m) {
    py::dict t;
    t["euler_characteristic"] = m.eulerCharacteristic;
    t["genus"] = m.genus;
    t["components"] = m.components;
    return t;
}

py::tuple meshArrays(const TriangleMesh& mesh) {
    py::array_t<float> vertices({py::ssize_t(mesh.positions.size()), py::ssize_t(3)});
    py::array_t<std::int32_t> triangles({py::ssize_t(mesh.triangles.size()), py::ssize_t(3)});
    auto v = vertices.mutable_unchecked<2>();
    auto t = triangles.mutable_unchecked<2>();
    for (std::size_t i = 0; i < mesh.positions.size(); ++i)
        for (int k = 0; k < 3; ++k)
            v(py::ssize_t(i), k) = mesh.positions[i][k];
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
        for (int k = 0; k < 3; ++k)
            t(py::ssize_t(i), k) = mesh.triangles[i][k];
    return py::make_tuple(vertices, triangles);
}

py::object toPyopenvdb(const std::string& bytes) {
    py::module_ vdb;
    try {
        vdb = py::module_::import("pyopenvdb");
    } catch (const py::error_already_set&) {
        throw py::import_error("to_pyopenvdb: pyopenvdb is not installed "
                               "(Debian: python3-openvdb, for /usr/bin/python3)");
    }
    // pyopenvdb's grids pickle as (their __dict__, the bytes of a VDB stream).
    py::object grid = vdb.attr("FloatGrid")();
    grid.attr("__setstate__")(py::make_tuple(py::dict(), py::bytes(bytes)));
    return grid;
}

// The methods a Shape and a Sculptor share. `with(self, read)` gives read(the shape now),
// computed without the GIL (and, for a Sculptor, while no other thread sculpts it).
template <typename Class, typename With> void addShapeMethods(Class& cls, const With& with) {
    using Self = typename Class::type;
    // A method that evaluates the shape at an n x 3 array of points, by `evaluate`.
    using AtPoints = std::vector<double> (Shape::*)(const std::vector<Eigen::Vector3d>&) const;
    const auto atPoints = [with](AtPoints evaluate, const char* name) {
        return [with, evaluate, name](const Self& s, const py::object& points) {
            const std::vector<Eigen::Vector3d> p = pointsOf(points, name);
            return arrayOf(with(s, [&](const Shape& x) { return (x.*evaluate)(p); }));
        };
    };
    cls.def_property_readonly(
           "volume",
           [with](const Self& s) {
               return with(s, [](const Shape& x) { return x.measures().volume; });
           },
           "The enclosed volume (world units cubed).")
        .def_property_readonly(
            "area",
            [with](const Self& s) {
                return with(s, [](const Shape& x) { return x.measures().area; });
            },
            "The surface area (world units squared).")
        .def_property_readonly(
            "voxel_size",
            [with](const Self& s) {
                return with(s, [](const Shape& x) { return x.grid().voxelSize()[0]; });
            },
            "The grid's voxel size.")
        .def_property_readonly(
            "topology",
            [with](const Self& s) {
                return topologyOf(with(s, [](const Shape& x) { return x.measures(); }));
            },
            "{'euler_characteristic', 'genus', 'components'} of the surface.")
        .def(
            "mesh",
            [with](const Self& s) {
                requireNumpy("mesh"); // before the surface is made
                return meshArrays(with(s, [](const Shape& x) { return x.mesh(); }));
            },
            "The surface as (vertices float32 n x 3, triangles int32 m x 3): the welded mesh "
            "that `sweepers-cli apply --mesh` exports.")
        .def("sample", atPoints(&Shape::sample, "sample"), py::arg("points"),
             "The grid's signed distance (trilinear, negative inside) at an n x 3 array of "
             "points.")
        .def("exact_distance", atPoints(&Shape::exactDistance, "exact_distance"), py::arg("points"),
             "The signed distance to the exact shape, to first order, at an n x 3 array of "
             "points: exact_value over the length of its gradient. Zero on the exact surface "
             "and negative inside; exact where the history carries the start rigidly and the "
             "start is a distance (a sphere); near the surface elsewhere, off by the square of "
             "the distance. Away from the surface it is not the distance to the shape: where "
             "no tool reached, it is the distance to the start's surface (docs/python.md).")
        .def("exact_value", atPoints(&Shape::exactValue, "exact_value"), py::arg("points"),
             "The exact shape's implicit function at an n x 3 array of points: the start's "
             "value at the point the inverse of every deformation applied takes them to, the "
             "reference `study` measures against; negative inside, zero on the exact surface, "
             "stretched or squeezed where the tools stretched or squeezed space.")
        .def(
            "to_vdb_bytes",
            [with](const Self& s) {
                return py::bytes(with(s, [](const Shape& x) { return x.vdbBytes(); }));
            },
            "The level set as a VDB stream in memory (openvdb::io::Stream), as `apply` "
            "writes it.")
        .def(
            "to_pyopenvdb",
            [with](const Self& s) {
                return toPyopenvdb(with(s, [](const Shape& x) { return x.vdbBytes(); }));
            },
            "The level set as a pyopenvdb.FloatGrid (needs pyopenvdb).")
        .def(
            "save",
            [with](const Self& s, const py::object& path, bool half) {
                const std::string p = pathOf(path);
                with(s, [&](const Shape& x) {
                    x.save(p, half);
                    return 0;
                });
            },
            py::arg("path"), py::arg("half") = false,
            "Writes the level set (.vdb) or its surface (.obj, .ply, .stl), atomically; "
            "half=True stores the .vdb's values as 16-bit floats (a third smaller, each value "
            "within a voxel of the surface rounded by under 1/2048 voxel).");
}

// A Sculptor's start: None (a unit sphere), a dict as a script's "start", or a path to a
// .vdb or a mesh.
py::object startFrom(const py::object& start) {
    if (start.is_none()) {
        py::dict sphere, at;
        at["center"] = py::make_tuple(0.0, 0.0, 0.0);
        at["radius"] = 1.0;
        sphere["sphere"] = at;
        return std::move(sphere);
    }
    if (py::isinstance<py::dict>(start)) return start;
    if (py::isinstance<py::str>(start) || isPath(start)) {
        const std::string path = pathOf(start);
        py::dict file;
        file[isMeshPath(path) ? "mesh" : "vdb"] = std::filesystem::absolute(path).string();
        return std::move(file);
    }
    throw py::type_error("start: None (a unit sphere), a dict such as {'sphere': {'center': "
                         "[0, 0, 0], 'radius': 1}}, or a path to a .vdb or a mesh");
}

std::vector<Stroke> strokesFrom(const py::object& strokes) {
    py::list list;
    if (py::isinstance<py::dict>(strokes))
        list.append(strokes);
    else if (py::isinstance<py::list>(strokes) || py::isinstance<py::tuple>(strokes))
        list = py::list(strokes);
    else
        throw py::type_error("strokes: a stroke (a dict) or a list of them");
    py::dict script;
    script["sweepers"] = 1;
    script["strokes"] = list;
    return loadStrokeScript(textOf(script, "the strokes"), "the strokes",
                            std::filesystem::current_path().string())
        .strokes;
}

// --- study -------------------------------------------------------------------------------

double voxelSizeOf(const py::handle& value) {
    if (py::isinstance<py::str>(value)) {
        const std::string text = value.cast<std::string>();
        try {
            std::size_t used = 0;
            const bool fraction = text.rfind("1/", 0) == 0;
            const double v = std::stod(fraction ? text.substr(2) : text, &used);
            if (used == text.size() - (fraction ? 2 : 0) && v > 0.0 && std::isfinite(v))
                return fraction ? 1.0 / v : v;
        } catch (const std::exception&) {
        }
        throw std::invalid_argument("voxel_sizes: '" + text +
                                    "' is not a voxel size (a number, or '1/N')");
    }
    return voxelSizeFrom(py::reinterpret_borrow<py::object>(value));
}

py::object study(const py::object& scripts, const py::object& voxelSizes,
                 const py::object& variants, const py::object& directory, bool force,
                 const py::object& progress, const std::string& keep, bool half) {
    std::optional<StudyOutputs> outputs = parseKept(keep);
    if (!outputs)
        throw std::invalid_argument("keep: '" + keep + "' is not one of both, grids, meshes, none");
    outputs->half = half;
    std::vector<std::string> paths;
    if (py::isinstance<py::str>(scripts) || isPath(scripts))
        paths.push_back(pathOf(scripts));
    else
        for (const py::handle s : scripts)
            paths.push_back(pathOf(s));
    std::vector<double> sizes;
    for (const py::handle h : voxelSizes)
        sizes.push_back(voxelSizeOf(h));
    std::sort(sizes.begin(), sizes.end(), std::greater<>());
    std::vector<StudyVariant> kinds;
    for (const py::handle v : py::isinstance<py::str>(variants) ? py::list(py::make_tuple(variants))
                                                                : py::list(variants)) {
        const std::string name = stringFrom(v, "variants");
        const auto kind = parseVariant(name);
        if (!kind)
            throw std::invalid_argument("variants: unknown variant '" + name + "' (" +
                                        variantNames() + ")");
        kinds.push_back(*kind);
    }
    if (paths.empty() || sizes.empty() || kinds.empty())
        throw std::invalid_argument("study: no script, voxel size or variant given");
    // Without a directory, a temporary one, removed after.
    py::object temporary;
    std::string dir;
    if (directory.is_none()) {
        temporary = py::module_::import("tempfile")
                        .attr("TemporaryDirectory")(py::arg("prefix") = "sweepers-study-");
        dir = temporary.attr("name").cast<std::string>();
    } else {
        dir = pathOf(directory);
    }
    StudyPlan plan = planStudy(paths, sizes, kinds, dir, force);
    plan.outputs = *outputs;
    std::filesystem::create_directories(plan.dir);
    const std::string json =
        runEngine(progress, "study", [&](Interrupter* stop, const Progress& report) {
            estimateStudyRuns(plan, int(loopThreads()));
            writeStudyPlan(plan);
            std::size_t done = 0;
            for (const PlannedRun& run : plan.runs) {
                if (!runIsDone(plan, run)) executeStudyRun(plan, run, stop);
                if (report) report(++done, plan.runs.size());
            }
            const StudyResults results = collectStudyResults(plan);
            mergeStudy(plan, results); // the plots need gnuplot; the rows do not
            nlohmann::json rows = nlohmann::json::array();
            for (const StudyRow& r : results.rows)
                rows.push_back(studyRowJson(r));
            return rows.dump();
        });
    if (temporary) temporary.attr("cleanup")();
    py::object rows = fromJson(json);
    try {
        return py::module_::import("pandas").attr("DataFrame")(rows);
    } catch (const py::error_already_set&) {
        return rows; // no pandas: the rows as dicts
    }
}

} // namespace

PYBIND11_MODULE(sweepers, m) {
    m.doc() = "Sweepers: sculpt narrow-band level sets with sweepers, measure them against the "
              "exact shape, mesh them into numpy, hand them to pyopenvdb. See docs/python.md.";
    m.attr("__version__") = SWEEPERS_VERSION;
    initVdb();
    // Files we did not write are read in a child process (io/isolated_read.h): here that
    // child is this interpreter, importing this module from where it was loaded.
    Dl_info self = {};
    const std::string python = py::module_::import("sys").attr("executable").cast<std::string>();
    if (!python.empty() && ::dladdr(reinterpret_cast<void*>(&onInterrupt), &self) != 0 &&
        self.dli_fname) {
        const std::string dir = std::filesystem::path(self.dli_fname).parent_path().string();
        setReaderCommand({python, "-c",
                          "import sys; sys.path.insert(0, " +
                              py::repr(py::str(dir)).cast<std::string>() + "); import sweepers"});
    }

    // The engine's errors as Python's, with the message the CLI prints.
    // pybind11's translators take the exception by value.
    // NOLINTNEXTLINE(performance-unnecessary-value-param)
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Cancelled&) {
            PyErr_SetNone(PyExc_KeyboardInterrupt);
        } catch (const ScriptError& e) {
            PyErr_SetString(PyExc_ValueError, e.what());
        } catch (const FileError& e) {
            PyErr_SetString(PyExc_OSError, e.what());
        }
    });

    // A refusal by the limits: the estimate, the limit and how to raise it.
    py::register_exception<LimitExceeded>(m, "LimitError", PyExc_RuntimeError);
    m.def(
        "set_limits",
        [](const py::object& maxMemory, const py::object& maxWork) {
            Limits l;
            const auto positive = [](const py::object& v, const std::string& what) {
                if (v.is_none()) return 0.0;
                const double x = numberFrom(v, what);
                if (!(x > 0.0 && std::isfinite(x)))
                    throw py::value_error(what + " must be a positive number or None");
                return x;
            };
            l.memoryBytes = positive(maxMemory, "max_memory");
            l.work = positive(maxWork, "max_work");
            setLimits(l);
        },
        py::arg("max_memory") = py::none(), py::arg("max_work") = py::none(),
        "Refuse work whose estimate exceeds `max_memory` bytes (None: half the memory "
        "available) or a stroke whose estimate exceeds `max_work` voxel updates (None: 2e9), "
        "with sweepers.LimitError, before it starts: as sweepers-cli's --max-memory and "
        "--max-work.");
    m.def(
        "limits",
        [] {
            py::dict d;
            d["max_memory"] = memoryLimitBytes();
            d["max_work"] = workLimit();
            return d;
        },
        "The limits in force: {'max_memory': bytes, 'max_work': voxel updates}.");

    m.def(
        "examples",
        [] {
            // Where the module is, not where the interpreter is: a module installed under a
            // prefix finds that prefix's examples (the sweepers-cli package's, from Debian).
            const std::string file =
                py::module_::import("sweepers").attr("__file__").cast<std::string>();
            std::string folder = modulePlaces(file).examples;
            if (!std::filesystem::is_directory(folder)) {
                const std::string why = "the examples are not installed at " + folder +
                                        " (Debian: apt install sweepers-cli)";
                PyErr_SetString(PyExc_FileNotFoundError, why.c_str());
                throw py::error_already_set();
            }
            return folder;
        },
        "The folder of the example stroke scripts: the installed ones (the sweepers-cli "
        "package's) or, for the module in a build tree, the checkout's data/.");

    py::class_<Shape> shape(m, "Shape",
                            "A sculpted level set with the history that made it "
                            "(sweepers.apply, Sculptor.shape()).");
    addShapeMethods(shape, [](const Shape& s, const auto& read) {
        // A Shape never changes: any number of threads may read it at once.
        py::gil_scoped_release release;
        return read(s);
    });

    m.def(
        "apply",
        [](const py::object& script, const py::object& voxelSize, const py::object& progress) {
            const GivenScript given = scriptFrom(script);
            const double h = voxelSizeFrom(voxelSize);
            return runEngine(progress, "apply", [&](Interrupter* stop, const Progress& report) {
                return python::applyScript(given.script, given.baseDir, h, stop, report);
            });
        },
        py::arg("script"), py::arg("voxel_size") = py::none(), py::arg("progress") = py::none(),
        "Applies a stroke script (a path, a JSON string or a dict) at its voxel size or "
        "`voxel_size`, as `sweepers-cli apply` does, and returns the Shape. `progress`: a "
        "callable (done, total), True for a tqdm bar, or None.");

    py::class_<Session> sculptor(m, "Sculptor",
                                 "A sculpting session: strokes applied one call at a time, "
                                 "each call one undo step. Its script() replays to the same "
                                 "grid.");
    sculptor
        .def(py::init([](const py::object& start, const py::object& voxelSize,
                         const py::object& halfWidth) {
                 py::dict script;
                 script["sweepers"] = 1;
                 py::dict grid;
                 const double h = voxelSizeFrom(voxelSize);
                 if (h > 0.0) grid["voxel_size"] = h;
                 if (!halfWidth.is_none()) grid["half_width"] = numberFrom(halfWidth, "half_width");
                 script["grid"] = grid;
                 script["start"] = startFrom(start);
                 script["strokes"] = py::list();
                 const std::string here = std::filesystem::current_path().string();
                 const StrokeScript parsed =
                     loadStrokeScript(textOf(script, "the start"), "the start", here);
                 return runEngine(py::none(), "start", [&](Interrupter* stop, const Progress&) {
                     return std::make_unique<Session>(parsed, here, stop);
                 });
             }),
             py::arg("start") = py::none(), py::arg("voxel_size") = py::none(),
             py::arg("half_width") = py::none(),
             "start: None (a unit sphere at the origin), a dict as a script's 'start' "
             "({'sphere': {...}}, {'vdb': path}, {'mesh': path}), or a path to a .vdb or a "
             "mesh; voxel_size and half_width: the grid's (default 0.02 and 3 voxels; a .vdb "
             "keeps its own).")
        .def(
            "apply",
            [](Session& s, const py::object& strokes, const py::object& progress) {
                const std::vector<Stroke> parsed = strokesFrom(strokes);
                runEngine(progress, "sculpting", [&](Interrupter* stop, const Progress& report) {
                    const Session::Turn turn(s);
                    s.apply(parsed, stop, report);
                    return 0;
                });
            },
            py::arg("strokes"), py::arg("progress") = py::none(),
            "Applies a stroke (a dict, as in a script's 'strokes') or a list of them, as one "
            "undo step. Ctrl-C (KeyboardInterrupt) stops it and leaves the Sculptor as it was.")
        .def(
            "undo",
            [](Session& s) {
                return runEngine(py::none(), "undo", [&](Interrupter*, const Progress&) {
                    const Session::Turn turn(s);
                    return s.undo();
                });
            },
            "Takes back the last apply(); False when there is none.")
        .def(
            "redo",
            [](Session& s) {
                return runEngine(py::none(), "redo", [&](Interrupter*, const Progress&) {
                    const Session::Turn turn(s);
                    return s.redo();
                });
            },
            "Applies again what undo() took back; False when there is none.")
        .def_property_readonly("can_undo",
                               [](const Session& s) {
                                   return withSession(s,
                                                      [](const Session& x) { return x.canUndo(); });
                               })
        .def_property_readonly("can_redo",
                               [](const Session& s) {
                                   return withSession(s,
                                                      [](const Session& x) { return x.canRedo(); });
                               })
        .def(
            "script",
            [](const Session& s) {
                return fromJson(withSession(
                    s, [](const Session& x) { return formatStrokeScript(x.script()); }));
            },
            "The session as a stroke script (a dict): its start and every stroke applied. "
            "`sweepers-cli apply` replays it to the same grid, voxel for voxel.")
        .def(
            "shape",
            [](const Session& s) {
                return withSession(s, [](const Session& x) { return x.shape(); });
            },
            "The shape now, as a Shape that later strokes do not change.");
    addShapeMethods(sculptor, [](const Session& s, const auto& read) {
        return withSession(s, [&](const Session& x) { return read(x.view()); });
    });

    // The variants' names from the list the parser reads; kept for the module's lifetime.
    static const std::string studyDoc =
        "Runs a grid-resolution study (docs/studies.md) of one or more scripts at each voxel "
        "size (numbers or '1/N') and variant (" +
        variantNames() +
        ") and returns its rows, keyed by the columns of study.csv: a pandas DataFrame when "
        "pandas is installed, else a list of dicts. In `directory` (kept, and resumed from) or "
        "a temporary one. `progress` sees runs done and in all. `keep`: what each run keeps beside "
        "its result (both, grids, meshes or none); `half`: its grid as 16-bit floats.";
    m.def("study", &study, py::arg("scripts"), py::arg("voxel_sizes"),
          py::arg("variants") = py::make_tuple(variantName(StudyVariant::Corrected)),
          py::arg("directory") = py::none(), py::arg("force") = false,
          py::arg("progress") = py::none(), py::arg("keep") = "both", py::arg("half") = false,
          studyDoc.c_str());
}
