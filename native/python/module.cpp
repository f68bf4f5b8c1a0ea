// module.cpp — the cloudgen_native extension module: thin bindings over the core.
//
// Plain CPython C API under the limited API (abi3, Python >= 3.11), so the one
// build loads in every Blender with Python 3.11 or later. Links only the pure
// core: no OpenVDB, OpenImageIO or TBB (docs/platform.md). numpy is imported at
// run time to create output arrays; its C headers are not used.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <string>

#include "arrays.h"
#include "cloudgen/density_block.h"
#include "cloudgen/field_key.h"
#include "cloudgen/frame_path.h"
#include "cloudgen/grid.h"
#include "cloudgen/model.h"
#include "cloudgen/parallel.h"
#include "cloudgen/param_io.h"
#include "cloudgen/tiers.h"
#include "convert.h"
#include "io/atomic_file.h"
#include "io/vdb_check.h"

namespace cgpy {
namespace {

constexpr long long kMaxImageSide = 8192;
constexpr long long kMaxThreads = 256;
constexpr std::int64_t kPointsPerTask = 4096;  // density(): work item of the parallel loop

int threads_arg(PyObject* o) {
  if (!o) return 0;
  const long long t = int_arg(o, "threads must be an integer in [0, 256] (0 = one per core)");
  if (t < 0 || t > kMaxThreads)
    raise(PyExc_ValueError, "threads must be an integer in [0, 256] (0 = one per core); got " + std::to_string(t));
  return static_cast<int>(t);
}

// ---------------------------------------------------------------- tables ---

PyObject* py_parameters(PyObject*, PyObject*) {
  return guarded([] {
    Ref list = check(PyList_New(cg::PARAM_COUNT));
    for (int i = 0; i < cg::PARAM_COUNT; ++i)
      check_status(PyList_SetItem(list.get(), i, declaration_to_py(static_cast<cg::P>(i)).release()));
    return list.release();
  });
}

PyObject* py_presets(PyObject*, PyObject*) {
  return guarded([] {
    Ref dict = check(PyDict_New());
    for (const cg::Preset& preset : cg::presets()) {
      Ref entry = check(PyDict_New());
      set_item(entry.get(), "description", str_to_py(preset.description.c_str()));
      set_item(entry.get(), "params", params_to_py(preset.params));
      Ref material = check(PyDict_New());
      for (const cg::MaterialValue& m : preset.material) {
        if (m.values.size() == 1) {
          set_item(material.get(), m.key.c_str(), check(PyFloat_FromDouble(m.values[0])));
        } else {
          Ref list = check(PyList_New(static_cast<Py_ssize_t>(m.values.size())));
          for (size_t i = 0; i < m.values.size(); ++i)
            check_status(PyList_SetItem(list.get(), static_cast<Py_ssize_t>(i),
                                        check(PyFloat_FromDouble(m.values[i])).release()));
          set_item(material.get(), m.key.c_str(), std::move(list));
        }
      }
      set_item(entry.get(), "material", std::move(material));
      set_item(dict.get(), preset.name.c_str(), std::move(entry));
    }
    return dict.release();
  });
}

PyObject* py_defaults(PyObject*, PyObject*) {
  return guarded([] { return params_to_py(cg::Params()).release(); });
}

PyObject* py_resolve_params(PyObject*, PyObject* params) {
  return guarded([&] { return params_to_py(params_from_py(params)).release(); });
}

PyObject* py_tiers(PyObject*, PyObject*) {
  return guarded([] {
    (void)cg::tiers();  // validates the data file (ParamError -> ValueError)
    Ref json_module = check(PyImport_ImportModule("json"));
    return check(PyObject_CallMethod(json_module.get(), "loads", "s", cg::tiers_json())).release();
  });
}

PyObject* py_field_key(PyObject*, PyObject* params) {
  return guarded([&] { return str_to_py(cg::field_key(params_from_py(params)).c_str()).release(); });
}

// The grid, key and metadata a bake of `params` gets: what `cloudgen bake` computes, so
// that a bake written elsewhere (inside Blender, through its own OpenVDB) is the CLI's.
PyObject* py_bake_plan(PyObject*, PyObject* args, PyObject* kwargs) {
  return guarded([&] {
    static const char* kwlist[] = {"params", "resolution", "lod", "half", "tolerance", nullptr};
    PyObject *params_obj = nullptr, *resolution_obj = nullptr, *tolerance_obj = nullptr;
    int lod = 1, half = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "OO|ppO:bake_plan", const_cast<char**>(kwlist), &params_obj,
                                     &resolution_obj, &lod, &half, &tolerance_obj))
      throw PyErrorSet{};
    const cg::Params params = params_from_py(params_obj);
    const long long resolution = int_arg(resolution_obj, "resolution must be an integer in [1, 100000]");
    if (resolution < 1 || resolution > 100000)
      raise(PyExc_ValueError, "resolution must be an integer in [1, 100000]; got " + std::to_string(resolution));
    cg::BakeOptions o;
    o.resolution = static_cast<int>(resolution);
    o.lod = lod != 0;
    if (tolerance_obj) {
      const double t = PyFloat_AsDouble(tolerance_obj);
      if (t == -1.0 && PyErr_Occurred()) throw PyErrorSet{};
      if (!(t >= 0.0 && t <= 1.0e30)) raise(PyExc_ValueError, "tolerance must be a number in [0, 1e30]");
      o.tolerance = static_cast<float>(t);
    }
    const cg::Model m = cg::prepare(params);
    const cg::GridSpec g = cg::bake_grid(m, o);
    const cg::Lod l = o.lod ? cg::lod_for_footprint(m, g.voxel) : cg::kNoLod;
    // the float32 values exactly (not their shortest decimal): the caller computes with them
    auto exact = [](float v) { return check(PyFloat_FromDouble(static_cast<double>(v))); };
    Ref dict = check(PyDict_New());
    Ref grid = check(PyList_New(3)), origin = check(PyList_New(3)), octaves = check(PyList_New(2));
    for (int a = 0; a < 3; ++a) {
      check_status(PyList_SetItem(grid.get(), a, check(PyLong_FromLong(g.n[a])).release()));
      check_status(PyList_SetItem(origin.get(), a, exact(g.origin[a]).release()));
    }
    check_status(PyList_SetItem(octaves.get(), 0, exact(l.worley_octaves).release()));
    check_status(PyList_SetItem(octaves.get(), 1, exact(l.perlin_octaves).release()));
    set_item(dict.get(), "grid", std::move(grid));
    set_item(dict.get(), "voxel", exact(g.voxel));
    set_item(dict.get(), "origin", std::move(origin));
    set_item(dict.get(), "key", str_to_py(cg::bake_key(m, o, half != 0).c_str()));
    set_item(dict.get(), "lod_octaves", std::move(octaves));
    set_item(dict.get(), "params_json", str_to_py(cg::params_to_json(params).c_str()));
    return dict.release();
  });
}

PyObject* py_version(PyObject*, PyObject*) {
  return guarded([] {
    Ref dict = check(PyDict_New());
    set_item(dict.get(), "version", str_to_py(cg::version()));
    set_item(dict.get(), "protocol", check(PyLong_FromLong(cg::kProtocolVersion)));
    return dict.release();
  });
}

// Longest pattern frame_path() takes: a file path, not a buffer of any size.
constexpr Py_ssize_t kMaxPatternBytes = 4096;

PyObject* py_frame_path(PyObject*, PyObject* args) {
  return guarded([&] {
    PyObject* pattern_obj = nullptr;
    PyObject* frame_obj = nullptr;
    if (!PyArg_ParseTuple(args, "OO:frame_path", &pattern_obj, &frame_obj)) throw PyErrorSet{};
    if (!PyUnicode_Check(pattern_obj)) raise(PyExc_TypeError, "pattern must be a str (a file path)");
    Py_ssize_t size = 0;
    const char* pattern = PyUnicode_AsUTF8AndSize(pattern_obj, &size);
    if (!pattern) throw PyErrorSet{};
    if (size > kMaxPatternBytes)
      raise(PyExc_ValueError,
            "pattern must be at most " + std::to_string(kMaxPatternBytes) + " bytes; got " + std::to_string(size));
    const long long frame = int_arg(frame_obj, "frame must be an integer in [-1000000, 1000000]");
    if (frame < -1000000 || frame > 1000000)
      raise(PyExc_ValueError, "frame must be an integer in [-1000000, 1000000]; got " + std::to_string(frame));
    const std::string path = cg::frame_path(std::string_view(pattern, static_cast<std::size_t>(size)), frame);
    return check(PyUnicode_FromStringAndSize(path.data(), static_cast<Py_ssize_t>(path.size()))).release();
  });
}

PyObject* py_check_vdb(PyObject*, PyObject* path_obj) {
  return guarded([&] {
    if (!PyUnicode_Check(path_obj)) raise(PyExc_TypeError, "path must be a str");
    Py_ssize_t size = 0;
    const char* path = PyUnicode_AsUTF8AndSize(path_obj, &size);
    if (!path) throw PyErrorSet{};
    if (size > kMaxPatternBytes) raise(PyExc_ValueError, "path must be at most 4096 bytes");
    cgio::VdbHeaderSummary summary;
    std::string error;
    without_gil([&] {
      try {
        summary = cgio::check_vdb_file(std::string(path, static_cast<std::size_t>(size)));
      } catch (const cgio::IoError& e) {
        error = e.what();
      }
    });
    if (!error.empty()) raise(PyExc_ValueError, error);
    Ref dict = check(PyDict_New());
    set_item(dict.get(), "version", check(PyLong_FromUnsignedLong(summary.version)));
    set_item(dict.get(), "grids", check(PyLong_FromLongLong(summary.grids)));
    set_item(dict.get(), "grids_checked", check(PyLong_FromLong(summary.grids_checked)));
    return dict.release();
  });
}

// ---------------------------------------------------------------- density ---

float footprint_arg(PyObject* o) {
  if (!o) return 0.0f;
  static const char* expect = "footprint must be a number >= 0 (scene units; 0 = every octave)";
  const double v = number_arg(o, expect);
  if (!std::isfinite(v) || v < 0.0 || v > 1e30) raise(PyExc_ValueError, std::string(expect) + "; got " + repr(o));
  return static_cast<float>(v);
}

PyObject* py_density(PyObject*, PyObject* args, PyObject* kwargs) {
  return guarded([&] {
    static const char* kwlist[] = {"params", "points", "threads", "footprint", nullptr};
    PyObject *params_obj = nullptr, *points_obj = nullptr, *threads_obj = nullptr, *footprint_obj = nullptr;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "OO|OO:density", const_cast<char**>(kwlist), &params_obj,
                                     &points_obj, &threads_obj, &footprint_obj))
      throw PyErrorSet{};
    const cg::Params params = params_from_py(params_obj);
    const int threads = threads_arg(threads_obj);
    const float footprint = footprint_arg(footprint_obj);
    const std::vector<float> points = points_from_py(points_obj);  // owned copy, safe without the GIL
    const auto n = static_cast<std::int64_t>(points.size() / 3);
    OutputArray out;
    new_float32_array(out, static_cast<Py_ssize_t>(n));
    float* result = out.data();  // held by out.buffer until we return
    without_gil([&] {
      const cg::Model model = cg::prepare(params);
      const cg::Lod lod = footprint > 0.0f ? cg::lod_for_footprint(model, footprint) : cg::kNoLod;
      const std::int64_t tasks = (n + kPointsPerTask - 1) / kPointsPerTask;
      cg::parallel_for(tasks, tasks > 1 ? cg::resolve_threads(threads) : 1, [&](std::int64_t task, int) {
        const std::int64_t begin = task * kPointsPerTask, end = std::min(n, begin + kPointsPerTask);
        std::vector<cg::vec3> batch(static_cast<std::size_t>(end - begin));  // evaluated in one batch
        for (std::size_t i = 0; i < batch.size(); ++i) {
          const float* p = &points[(static_cast<std::size_t>(begin) + i) * 3];
          batch[i] = cg::vec3{p[0], p[1], p[2]};
        }
        cg::density_block(model, batch.data(), batch.size(), lod, result + begin);
      });
    });
    return out.array.release();
  });
}

// ------------------------------------------------------------------ slice ---

int axis_arg(PyObject* o) {
  static const char* expect = "axis must be 'x', 'y', 'z' or 0, 1, 2";
  if (PyUnicode_Check(o)) {
    Py_ssize_t size = 0;
    const char* s = PyUnicode_AsUTF8AndSize(o, &size);
    if (!s) throw PyErrorSet{};
    if (size == 1) {
      const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(s[0])));
      if (c >= 'x' && c <= 'z') return c - 'x';
    }
    raise(PyExc_ValueError, std::string(expect) + "; got " + repr(o));
  }
  const long long a = int_arg(o, expect);
  if (a < 0 || a > 2) raise(PyExc_ValueError, std::string(expect) + "; got " + repr(o));
  return static_cast<int>(a);
}

int side_arg(PyObject* o, const char* name) {
  const std::string expect = std::string(name) + " must be an integer in [1, " + std::to_string(kMaxImageSide) + "]";
  const long long v = int_arg(o, expect.c_str());
  if (v < 1 || v > kMaxImageSide) raise(PyExc_ValueError, expect + "; got " + repr(o));
  return static_cast<int>(v);
}

float offset_arg(PyObject* o) {
  static const char* expect = "offset must be a number in [0, 1]";
  const double v = number_arg(o, expect);
  if (!std::isfinite(v) || v < 0.0 || v > 1.0) raise(PyExc_ValueError, std::string(expect) + "; got " + repr(o));
  return static_cast<float>(v);
}

PyObject* py_slice(PyObject*, PyObject* args, PyObject* kwargs) {
  return guarded([&] {
    static const char* kwlist[] = {"params", "axis", "offset", "width", "height", "lod", "threads", nullptr};
    PyObject *params_obj = nullptr, *axis_obj = nullptr, *offset_obj = nullptr, *width_obj = nullptr,
             *height_obj = nullptr, *threads_obj = nullptr;
    int lod = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "OOOOO|pO:slice", const_cast<char**>(kwlist), &params_obj, &axis_obj,
                                     &offset_obj, &width_obj, &height_obj, &lod, &threads_obj))
      throw PyErrorSet{};
    const cg::Params params = params_from_py(params_obj);
    cg::SliceSpec spec;
    spec.axis = axis_arg(axis_obj);
    spec.offset = offset_arg(offset_obj);
    spec.width = side_arg(width_obj, "width");
    spec.height = side_arg(height_obj, "height");
    spec.lod = lod != 0;
    spec.threads = threads_arg(threads_obj);
    OutputArray out;
    new_float32_array(out, spec.height, spec.width);
    float* result = out.data();  // held by out.buffer until we return
    without_gil([&] {
      const cg::Model model = cg::prepare(params);
      const std::vector<float> image = cg::slice(model, spec);
      std::memcpy(result, image.data(), image.size() * sizeof(float));
    });
    return out.array.release();
  });
}

PyObject* py_slice_display_scale(PyObject*, PyObject* peak) {
  return guarded([&] {
    const double v = number_arg(peak, "peak must be a number");
    return check(PyFloat_FromDouble(cg::slice_display_scale(static_cast<float>(v)))).release();
  });
}

// ----------------------------------------------------------------- module ---

PyMethodDef kMethods[] = {
    {"parameters", py_parameters, METH_NOARGS,
     "parameters()\n--\n\n"
     "The parameter declarations, in order: a list of dicts with name, label, group,\n"
     "kind ('float', 'int', 'vector', 'curve'), count, default, min, max, soft_min,\n"
     "soft_max, map (lo, hi: physical = lo + (hi - lo) * value), unit and help."},
    {"presets", py_presets, METH_NOARGS,
     "presets()\n--\n\n"
     "The cloud types: dict name -> {'description': str, 'params': {name: value},\n"
     "'material': {'anisotropy': float, 'color': [r, g, b], 'step_rate': float, 'halo': float}}\n"
     "(material keys are optional suggestions for the volume shader)."},
    {"defaults", py_defaults, METH_NOARGS,
     "defaults()\n--\n\n"
     "Every parameter at its declared default, as a params dict."},
    {"resolve_params", py_resolve_params, METH_O,
     "resolve_params(params, /)\n--\n\n"
     "Validates a params dict and returns every parameter's value (the optional\n"
     "'preset' applied, missing keys filled in). Raises ValueError/TypeError naming\n"
     "the key and the accepted range."},
    {"density", reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)(void)>(py_density)),
     METH_VARARGS | METH_KEYWORDS,
     "density(params, points, threads=0, footprint=0.0)\n--\n\n"
     "Cloud density at points in the cloud object's local frame (the box is\n"
     "centred on the origin, box_size across). params: dict keyed by parameter\n"
     "names (missing keys take their defaults; 'preset' names the base cloud type)\n"
     "or None. points: array-like of shape (N, 3); NaN, Inf and points outside the\n"
     "box give 0. Returns float32 array (N,).\n"
     "threads: 0 = one per core. footprint > 0: the level of detail a bake with\n"
     "that voxel edge uses (octaves finer than it are replaced by their mean).\n"
     "Releases the GIL while evaluating."},
    {"tiers", py_tiers, METH_NOARGS,
     "tiers()\n--\n\n"
     "The quality tiers (native/presets/tiers.json) in order Draft, Preview, Final:\n"
     "dict name -> {'label', 'description', 'render': {'samples', 'step_rate'},\n"
     "'bake': {'resolution', 'lod', 'tolerance', 'half'}, 'preview': {'size'},\n"
     "'measured': {scene: {figures from bench/accuracy}}}."},
    {"field_key", py_field_key, METH_O,
     "field_key(params, /)\n--\n\n"
     "16 hex digits identifying the density field of a params dict: equal keys mean\n"
     "equal fields (time drops out of a cloud without wind and evolution)."},
    {"bake_plan", reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)(void)>(py_bake_plan)),
     METH_VARARGS | METH_KEYWORDS,
     "bake_plan(params, resolution, lod=True, half=False, tolerance=0.0)\n--\n\n"
     "What `cloudgen bake --resolution N` computes before it bakes: {'grid': [nx, ny, nz],\n"
     "'voxel', 'origin' (corner of voxel 0, local frame; voxel (i,j,k) has its centre at\n"
     "origin + (i + 1/2) * voxel, in float32), 'key' (the bake key stored in the file),\n"
     "'lod_octaves' [worley, gradient], 'params_json' (the cloudgen_params metadata)}."},
    {"version", py_version, METH_NOARGS,
     "version()\n--\n\n"
     "{'version': release, 'protocol': N}: the release of this module and the version of\n"
     "the CLI's JSON-lines protocol it was built with (docs/cli_protocol.md). A program\n"
     "that ships the module and the CLI checks once that `cloudgen --version --json` agrees."},
    {"check_vdb", py_check_vdb, METH_O,
     "check_vdb(path, /)\n--\n\n"
     "Cheap checks of a .vdb file before any OpenVDB reads it (no OpenVDB involved):\n"
     "a regular file (a FIFO is refused at once), magic, file version, header, grid\n"
     "descriptors and the metadata at known places. Returns {'version', 'grids',\n"
     "'grids_checked'}; ValueError with a one-line reason for a file to leave alone\n"
     "(docs/hostile_inputs.md). Releases the GIL."},
    {"frame_path", py_frame_path, METH_VARARGS,
     "frame_path(pattern, frame, /)\n--\n\n"
     "The file of a sequence frame, named exactly as `cloudgen bake` names it: the last\n"
     "run of '#' becomes the frame number zero-padded to the run's length, else _NNNN\n"
     "goes before the extension. frame in [-1000000, 1000000]."},
    {"slice", reinterpret_cast<PyCFunction>(reinterpret_cast<void (*)(void)>(py_slice)), METH_VARARGS | METH_KEYWORDS,
     "slice(params, axis, offset, width, height, lod=False, threads=0)\n--\n\n"
     "Cross-section through the cloud box perpendicular to axis ('x', 'y', 'z' or\n"
     "0-2) at generated coordinate offset in [0, 1]; width and height in [1, 8192].\n"
     "Returns float32 array (height, width), row 0 at the top. Columns/rows: axis x\n"
     "-> +y / z, axis y -> +x / z, axis z -> +x / y; pixel centres are sampled.\n"
     "lod limits noise octaves to the pixel footprint. Releases the GIL."},
    {"slice_display_scale", py_slice_display_scale, METH_O,
     "slice_display_scale(peak, /)\n--\n\n"
     "The display scale S of a slice whose largest density is peak: max(peak / 3,\n"
     "0.001) (0.001 for a peak that is not finite). The eye sees grey = 1 - exp(-density / S),\n"
     "as in the PNG of `cloudgen preview`."},
    {nullptr, nullptr, 0, nullptr},
};

int exec_module(PyObject* module) { return PyModule_AddStringConstant(module, "__version__", cg::version()); }

PyModuleDef_Slot kSlots[] = {
    {Py_mod_exec, reinterpret_cast<void*>(exec_module)},
    {0, nullptr},
};

PyModuleDef kModule = {
    PyModuleDef_HEAD_INIT,
    "cloudgen_native",
    "Procedural volumetric clouds: thin bindings over the cloudgen C++ core\n"
    "(parameters, presets, density at points, cross-section slices).",
    0,
    kMethods,
    kSlots,
    nullptr,
    nullptr,
    nullptr,
};

}  // namespace
}  // namespace cgpy

PyMODINIT_FUNC PyInit_cloudgen_native(void) { return PyModuleDef_Init(&cgpy::kModule); }
