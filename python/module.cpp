// quadlod Python module (issue 22): quadlod.simplify / lod_chain / evaluate over NumPy arrays.
//
// The extension is `quadlod._core`; the package `quadlod` (addons/blender/quadlod/__init__.py,
// which is also the Blender add-on) re-exports it. Every error the CLI would print after
// "quadlod: " becomes a quadlod.QuadlodError (a ValueError) with the same text; unknown or
// mistyped options become TypeError. The GIL is released while the pipeline runs.
#include "mesh_arrays.h"

#include "mesh/connectivity.h"
#include "mesh/validation.h"
#include "quadlod/io.h"
#include "quadlod/metrics.h"
#include "quadlod/lod.h"
#include "quadlod/protect.h"
#include "quadlod/simplify.h"

#include <pybind11/stl.h>

#include <cmath>
#include <functional>
#include <map>
#include <vector>

namespace quadlod::python {

namespace {

/// The keyword options of simplify() / lod_chain(): name → how it sets SimplifyOptions.
/// Names follow the CLI's long options with '-' → '_' (docs in README "Python module").
using OptionSetter = std::function<void(SimplifyOptions&, const py::handle&)>;

template <class T>
OptionSetter set_field(T SimplifyOptions::*field) {
  return [field](SimplifyOptions& o, const py::handle& v) { o.*field = v.cast<T>(); };
}

/// A choice (an enum of SimplifyOptions) by one of its names (include/quadlod/simplify.h); any
/// other name is a ValueError listing them: "objective: 'shape' or 'paper', not 'bogus'".
template <class E>
OptionSetter set_choice(E SimplifyOptions::*field, const char* key, std::vector<std::pair<std::string, E>> names) {
  return [field, key, names = std::move(names)](SimplifyOptions& o, const py::handle& v) {
    const std::string chosen = v.cast<std::string>();
    std::string list;
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (names[i].first == chosen) {
        o.*field = names[i].second;
        return;
      }
      list += (i == 0 ? "'" : i + 1 == names.size() ? " or '" : ", '") + names[i].first + "'";
    }
    throw py::value_error(std::string(key) + ": " + list + ", not '" + chosen + "'");
  };
}

const std::map<std::string, OptionSetter>& option_table() {
  static const std::map<std::string, OptionSetter> table = {
      {"objective", set_choice(&SimplifyOptions::objective, "objective", objective_names())},
      {"lambda_shape", set_field(&SimplifyOptions::lambda_shape)},
      {"triangle_collapse_factor", set_field(&SimplifyOptions::triangle_collapse_factor)},
      {"max_triangle_share", set_field(&SimplifyOptions::max_triangle_share)},
      {"triangle_penalty", set_field(&SimplifyOptions::triangle_penalty)},
      {"swap_rounds", set_field(&SimplifyOptions::swap_rounds)},
      {"shape_flip_angle", set_field(&SimplifyOptions::shape_flip_angle_deg)},
      {"effort", set_field(&SimplifyOptions::effort)},
      {"time_limit", set_field(&SimplifyOptions::time_limit_seconds)},
      {"time_bound", set_field(&SimplifyOptions::time_bound_seconds)},
      {"threads", set_field(&SimplifyOptions::threads)},
      {"seed", set_field(&SimplifyOptions::seed)},
      {"formulation", [](SimplifyOptions& o, const py::handle& v) {
         const std::string f = v.cast<std::string>();
         if (f != "fast" && f != "exact") throw py::value_error("formulation: 'fast' or 'exact', not '" + f + "'");
         o.exact_formulation = f == "exact";
       }},
      {"strategy", set_choice(&SimplifyOptions::strategy, "strategy", selection_strategy_names())},
      {"neighbourhood_groups", set_field(&SimplifyOptions::neighbourhood_groups)},
      {"stall_seconds", set_field(&SimplifyOptions::stall_seconds)},
      {"epsilon_n", set_field(&SimplifyOptions::epsilon_n)},
      {"epsilon_theta", set_field(&SimplifyOptions::epsilon_theta_deg)},
      {"lambda_geo", set_field(&SimplifyOptions::lambda_geo)},
      {"lambda_edge", set_field(&SimplifyOptions::lambda_edge)},
      {"lambda_tri", set_field(&SimplifyOptions::lambda_tri)},
      {"max_hausdorff", set_field(&SimplifyOptions::max_hausdorff)},
      {"max_rounds", set_field(&SimplifyOptions::max_rounds)},
      {"pass_ratio", set_field(&SimplifyOptions::pass_ratio)},
      {"max_passes", set_field(&SimplifyOptions::max_passes)},
      {"greedy_fallback", set_field(&SimplifyOptions::greedy_fallback)},
      {"features", set_field(&SimplifyOptions::features)},
      {"place_on_hard_edges", set_field(&SimplifyOptions::place_on_hard_edges)},
      {"hard_angle", set_field(&SimplifyOptions::hard_angle_deg)},
      {"surface_fit", set_field(&SimplifyOptions::surface_fit_iterations)},
      {"recover_quads", set_choice(&SimplifyOptions::recover_quads, "recover_quads", quad_recovery_names())},
      {"seams", set_choice(&SimplifyOptions::seams, "seams", seam_policy_names())},
      {"bend_lines_below", set_field(&SimplifyOptions::bend_lines_below_ratio)},  // issue 32
      {"max_line_tolerance", set_field(&SimplifyOptions::max_line_tolerance)},
      {"surface_fit_vertex_weight", set_field(&SimplifyOptions::surface_fit_vertex_weight)},
      {"morph_weight", set_field(&SimplifyOptions::morph_error_weight)},  // issue 34
      {"decide_on_doubles", [](SimplifyOptions& o, const py::handle& v) { o.float32_decisions = !v.cast<bool>(); }},
      {"consistency", set_field(&SimplifyOptions::consistency)},
      {"segmentation", set_field(&SimplifyOptions::segmentation)},
      {"geometry", set_field(&SimplifyOptions::geometry)},
      {"dual_repair", set_field(&SimplifyOptions::dual_repair)},
      {"progress", set_field(&SimplifyOptions::progress)},
      // Issue 34 (docs/protect.md): one weight per vertex in [0, 1] (a 1-D array or sequence), or
      // a colour channel; simplify() checks the count and the range.
      {"protect", [](SimplifyOptions& o, const py::handle& v) {
         const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(v);
         if (!a || a.ndim() != 1) throw py::type_error("protect: a 1-D array of one weight per vertex, in [0, 1]");
         o.protect_weights.assign(a.data(), a.data() + a.size());
       }},
      {"protect_from", set_choice(&SimplifyOptions::protect_channel, "protect_from", protect_channel_names())},
      {"protect_strength", set_field(&SimplifyOptions::protect_strength)},
      {"protect_importance", set_field(&SimplifyOptions::protect_importance)},
      // --- symmetry (issue 34; docs/symmetry.md) ---
      {"symmetry", set_choice(&SimplifyOptions::symmetry, "symmetry", symmetry_names())},
      {"symmetry_tolerance", set_field(&SimplifyOptions::symmetry_tolerance)},
  };
  return table;
}

/// The ranges the CLI checks (apps/quadlod/cmd_simplify.cpp), so that a script gets the same
/// refusal as a command line instead of a silently clamped run.
void check_ranges(const SimplifyOptions& o) {
  auto in = [](double v, double lo, double hi, const char* name) {
    if (!(v >= lo && v <= hi))
      throw py::value_error(std::string(name) + ": " + std::to_string(v) + " is not in [" + std::to_string(lo) +
                            ", " + std::to_string(hi) + "]");
  };
  in(o.ratio, 1e-6, 1.0, "ratio");
  in(o.time_limit_seconds, 0.0, 86400.0, "time_limit");
  in(o.threads, 0, 256, "threads");
  in(o.epsilon_n, 0.0, 0.5, "epsilon_n");
  in(o.hard_angle_deg, 0.0, 180.0, "hard_angle");
  in(o.max_hausdorff, 0.0, 1.0, "max_hausdorff");
  in(o.max_rounds, 1, 64, "max_rounds");
  in(o.surface_fit_iterations, 0, 100, "surface_fit");
  in(o.surface_fit_vertex_weight, 0.0, 100.0, "surface_fit_vertex_weight");
  in(o.symmetry_tolerance, 1e-9, 0.1, "symmetry_tolerance");  // issue 34
  in(o.morph_error_weight, 0.0, 100.0, "morph_weight");  // issue 34
}

SimplifyOptions options_from_kwargs(const py::kwargs& kwargs) {
  SimplifyOptions options;
  options.progress = false;  // a library call prints nothing unless asked
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    const auto it = option_table().find(name);
    if (it == option_table().end()) throw py::type_error("unknown option '" + name + "'");
    try {
      it->second(options, value);
    } catch (const py::cast_error&) {
      throw py::type_error("option '" + name + "': wrong type " + std::string(py::str(py::type::of(value))));
    }
  }
  return options;
}

/// ratio / faces_target exactly as the CLI's --ratio / --faces (one of them, not both).
void set_target(SimplifyOptions& options, const py::object& ratio, const py::object& faces_target) {
  if (!ratio.is_none() && !faces_target.is_none())
    throw py::value_error("give ratio or faces_target, not both");
  if (ratio.is_none() && faces_target.is_none()) throw py::value_error("give a target: ratio=R or faces_target=N");
  if (!ratio.is_none()) {
    try {
      options.ratio = ratio.cast<double>();
    } catch (const py::cast_error&) {
      throw py::type_error("ratio: a number in (0, 1]");
    }
  } else {
    long long n = 0;
    try {
      n = faces_target.cast<long long>();
    } catch (const py::cast_error&) {
      throw py::type_error("faces_target: an integer (triangle-equivalents)");
    }
    if (n < 1) throw py::value_error("faces_target: must be >= 1 (triangle-equivalents: quad = 2, k-gon = k - 2)");
    options.ratio = 1.0;
    options.target_tri_equivalent = static_cast<std::uint64_t>(n);
  }
}

py::object json_to_python(const nlohmann::json& j) {
  // NaN / inf cannot appear: the reports are built from finite numbers or null.
  return py::module_::import("json").attr("loads")(j.dump());
}

py::dict result_to_dict(const SimplifyResult& r, bool uvs_as_dict) {
  py::dict out = mesh_to_dict(r.mesh, uvs_as_dict);
  nlohmann::json report = r.report;
  report["input_tri_equivalent"] = r.input_tri_equivalent;
  report["target"] = r.target;
  report["achieved"] = r.achieved;
  report["quads"] = r.quads;
  report["triangles"] = r.triangles;
  report["ngons"] = r.ngons;
  report["passes_used"] = r.passes_used;
  report["note"] = r.note;
  out["report"] = json_to_python(report);
  // Issue 34: the output vertices' protect weights (the largest of the vertices merged into each).
  if (!r.protect_weights.empty()) {
    py::array_t<double> weights(static_cast<py::ssize_t>(r.protect_weights.size()));
    std::copy(r.protect_weights.begin(), r.protect_weights.end(), weights.mutable_data());
    out["protect"] = weights;
  }
  return out;
}

SimplifyResult run_simplify(const PolyMesh& mesh, const SimplifyOptions& options) {
  SimplifyResult r;
  {
    py::gil_scoped_release unlocked;
    r = simplify(mesh, options);
  }
  if (!r.ok()) throw MeshInputError{r.error};
  return r;
}

/// The LOD chain through the library's lod_chain() (include/quadlod/lod.h): level k reduced from
/// level k − 1's output to ratios[k] × the input's triangle-equivalents, each level measured
/// against the input (Hausdorff, screen-size switch threshold) unless measure_hausdorff is off.
struct ChainLevel {
  SimplifyResult result;
  double hausdorff = 0.0, screen_size = 0.0;
};
std::vector<ChainLevel> run_lod_chain(const PolyMesh& input, const std::vector<double>& ratios,
                                      const SimplifyOptions& options, bool measure_hausdorff) {
  LodChainParams params;
  params.ratios = ratios;
  params.simplify = options;
  params.measure_hausdorff = measure_hausdorff;
  LodChainResult chain;
  {
    py::gil_scoped_release unlocked;
    chain = lod_chain(input, params);
  }
  if (!chain.ok()) throw MeshInputError{chain.error};
  std::vector<ChainLevel> out;
  for (LodLevel& level : chain.levels) {
    ChainLevel l;
    SimplifyResult& r = l.result;
    r.mesh = std::move(level.mesh);
    r.report = std::move(level.report);
    r.note = level.note;
    r.input_tri_equivalent = chain.input_tri_equivalent;
    r.target = level.target;
    r.achieved = level.achieved;
    r.quads = level.quads;
    r.triangles = level.triangles;
    r.ngons = level.ngons;
    l.hausdorff = level.hausdorff;
    l.screen_size = level.screen_size;
    out.push_back(std::move(l));
  }
  return out;
}

py::dict evaluate_to_dict(const PolyMesh& input, const PolyMesh& output, const EvalParams& params) {
  EvalResult r;
  MeshStats validity, input_validity;
  {
    py::gil_scoped_release unlocked;
    r = evaluate(input, output, params);
    if (r.ok()) {
      validity = compute_stats(output, build_connectivity(output));
      input_validity = compute_stats(input, build_connectivity(input));
    }
  }
  if (!r.ok()) throw MeshInputError{"output: " + r.error};
  // The keys of `quadlod eval --json` (apps/quadlod/cmd_eval.cpp), without the file names.
  nlohmann::json j = to_json(r);
  j["tri_equivalent_in"] = r.counts_in.tri_equivalent;
  j["tri_equivalent_out"] = r.counts_out.tri_equivalent;
  j["validity"] = validity_json(validity, input_validity);
  return json_to_python(j);
}

}  // namespace

}  // namespace quadlod::python

PYBIND11_MODULE(_core, m) {
  using namespace quadlod;
  using namespace quadlod::python;
  namespace py = pybind11;
  m.doc() = "quadlod: quad-dominant mesh reduction that keeps edge loops (C++ core).";
  m.attr("__version__") = QUADLOD_VERSION;  // CMake's project(VERSION), as the wheel's (setup.py)
  static py::exception<MeshInputError> error(m, "QuadlodError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const MeshInputError& e) {
      PyErr_SetString(error.ptr(), e.message.c_str());
    }
  });

  m.def(
      "simplify",
      [](py::object vertices, py::object faces, py::object ratio, py::object faces_target, py::object uvs,
         py::object normals, py::object materials, py::object morph_targets, py::kwargs kwargs) {
        SimplifyOptions options = options_from_kwargs(kwargs);
        set_target(options, ratio, faces_target);
        check_ranges(options);
        PolyMesh mesh = mesh_from_arrays(vertices, faces, uvs, normals, materials);
        read_morph_targets(mesh, morph_targets);  // issue 34
        return result_to_dict(run_simplify(mesh, options), py::isinstance<py::dict>(uvs));
      },
      py::arg("vertices"), py::arg("faces"), py::kw_only(), py::arg("ratio") = py::none(),
      py::arg("faces_target") = py::none(), py::arg("uvs") = py::none(), py::arg("normals") = py::none(),
      py::arg("materials") = py::none(), py::arg("morph_targets") = py::none(),
      R"(Reduces a polygon mesh, keeping its quad layout (the CLI's `quadlod simplify`).

vertices: (V, 3) floats. faces: (corner_vertices, face_sizes) — flat corner indices and the
corner count of each face, as Blender and trimesh hold polygons — or an (F, k) array.
ratio: target as a fraction of the input's triangle-equivalents (quad = 2, k-gon = k - 2), or
faces_target: that count. uvs: per-corner (C, 2) or {name: (C, 2)}; normals: per-corner (C, 3);
materials: per-face slot index (F,). morph_targets: blend shapes, {name: (V, 3) per-vertex
displacements} (Blender: shape key co - basis co), carried to the output's vertices and counted
in the error with weight morph_weight (docs/blend_shapes.md). Further keywords are the CLI's options with '_' for '-'
(objective, effort, time_limit, time_bound, threads, seed, features, hard_angle, max_hausdorff, pass_ratio,
surface_fit, surface_fit_vertex_weight, ...). protect: one weight per vertex in [0, 1] (V,) — 1 keeps
the vertex exactly and the edges between such vertices, between 0 and 1 makes collapses there
cost more (docs/protect.md); or protect_from='color:r' (the vertex colours' channel).
Returns a dict: vertices, faces, face_sizes, [uvs, normals, materials, protect, morph_targets] of the reduced mesh and
report (the JSON report of `simplify --report`, plus target/achieved/quads/triangles/ngons).
Raises QuadlodError with the CLI's message on bad input.)");

  m.def(
      "lod_chain",
      [](py::object vertices, py::object faces, py::object ratios, int levels, double ratio, py::object uvs,
         py::object normals, py::object materials, py::object morph_targets, bool measure_hausdorff, py::kwargs kwargs) {
        SimplifyOptions options = options_from_kwargs(kwargs);
        std::vector<double> chain;
        if (!ratios.is_none()) chain = ratios.cast<std::vector<double>>();
        else {
          if (levels < 1 || levels > 16) throw py::value_error("levels: 1 to 16");
          if (!(ratio > 0 && ratio < 1)) throw py::value_error("ratio: the per-level ratio must be in (0, 1)");
          for (int k = 1; k <= levels; ++k) chain.push_back(std::pow(ratio, k));
        }
        if (chain.empty()) throw py::value_error("ratios: give at least one level");
        for (std::size_t k = 0; k < chain.size(); ++k)
          if (!(chain[k] > 0 && chain[k] < 1) || (k > 0 && chain[k] >= chain[k - 1]))
            throw py::value_error("ratios: each in (0, 1) and below the previous level's");
        options.ratio = chain.front();
        check_ranges(options);
        PolyMesh mesh = mesh_from_arrays(vertices, faces, uvs, normals, materials);
        read_morph_targets(mesh, morph_targets);  // issue 34
        py::list out;
        for (const ChainLevel& level : run_lod_chain(mesh, chain, options, measure_hausdorff)) {
          py::dict d = result_to_dict(level.result, py::isinstance<py::dict>(uvs));
          d["hausdorff"] = level.hausdorff;
          d["screen_size"] = level.screen_size;
          out.append(d);
        }
        return out;
      },
      py::arg("vertices"), py::arg("faces"), py::kw_only(), py::arg("ratios") = py::none(), py::arg("levels") = 3,
      py::arg("ratio") = 0.5, py::arg("uvs") = py::none(), py::arg("normals") = py::none(),
      py::arg("materials") = py::none(), py::arg("morph_targets") = py::none(), py::arg("measure_hausdorff") = true,
      R"(An LOD chain: a list of simplify() results, level k reduced from level k - 1.

ratios: each level's size as a fraction of the INPUT's triangle-equivalents, decreasing
(default: ratio ** k for k = 1..levels). Each result also has 'hausdorff' (to the input, over its
longest bbox side) and 'screen_size' (the switch threshold of docs/lod.md), NaN when
measure_hausdorff is False. Other arguments as simplify().)");

  m.def(
      "read_mesh",
      [](const std::string& path) {
        ReadResult r;
        {
          py::gil_scoped_release unlocked;
          r = quadlod::read_mesh(path);
        }
        if (!r.ok()) throw MeshInputError{r.error};
        return mesh_to_dict(r.mesh, /*uvs_as_dict=*/true);
      },
      py::arg("path"),
      R"(Reads an OBJ / PLY / OFF file (as the CLI does) into the dict simplify() returns; UV layers
as a dict by name. Raises QuadlodError with the CLI's message ("file:line: ...").)");

  m.def(
      "write_mesh",
      [](py::object mesh, const std::string& path) {
        const PolyMesh polymesh = mesh_from_object(mesh);
        WriteResult w;
        {
          py::gil_scoped_release unlocked;
          w = quadlod::write_mesh(polymesh, path);
        }
        if (!w.ok()) throw MeshInputError{w.error};
        return w.warnings;
      },
      py::arg("mesh"), py::arg("path"),
      R"(Writes a mesh dict (or (vertices, faces[, face_sizes])) to OBJ / PLY / OFF, atomically.
Returns the writer's warnings (what the format could not hold).)");

  m.def(
      "evaluate",
      [](py::object input, py::object output, std::uint64_t samples, std::uint64_t seed, unsigned threads) {
        if (samples < 1000) throw py::value_error("samples: at least 1000");
        EvalParams params;
        params.samples = samples;
        params.seed = seed;
        params.threads = threads;
        const PolyMesh in = mesh_from_object(input);
        const PolyMesh out = mesh_from_object(output);
        return evaluate_to_dict(in, out, params);
      },
      py::arg("input"), py::arg("output"), py::kw_only(), py::arg("samples") = EvalParams{}.samples,
      py::arg("seed") = EvalParams{}.seed, py::arg("threads") = 0u,
      R"(The metrics of `quadlod eval --json` of output against input.

input, output: dicts with vertices / faces [/ face_sizes / uvs / materials] (what simplify()
returns) or tuples (vertices, faces[, face_sizes]). Returns a dict (chamfer, hausdorff, qpr,
pccd, flow, seams, UV, material and validity figures; docs/metrics.md).)");
}
