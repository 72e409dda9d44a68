// quadlod — quad-dominant mesh reduction, the whole pipeline of the paper's Fig. 2:
//
//   input ─► connectivity ─► analysis (poly-chords §3.1, segments §3.2.2, clusters §3.2.3–4)
//         ─► edge selection (ILP §3.2, Eqs. 1–9) ─► dual repair (§3.3.1)
//         ─► cluster collapse (§3.3.2) ─► output
//
// Sizes are triangle-equivalents, as the paper counts faces: a triangle is 1, a quad 2, a
// k-gon k − 2. The options here are the knobs a user turns; every stage has more parameters
// with documented defaults in its own header under src/ (docs/parameters.md lists them).
#pragma once

#include "quadlod/mesh.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace quadlod {

struct SimplifyOptions {
  /// Target as a fraction of the input's triangle-equivalents, in (0, 1]; or, when
  /// `target_tri_equivalent` > 0, that absolute count (which then wins).
  double ratio = 0.5;
  std::uint64_t target_tri_equivalent = 0;

  // --- the paper's parameters (defaults: the paper's values where it gives one) ---------------
  double epsilon_n = 0.03;          ///< Eq. 2 slack
  double epsilon_theta_deg = 60.0;  ///< §3.2.2 breakpoint angle (π/3)
  double lambda_geo = -1.0;         ///< Eq. 9; < 0 = the measured default (docs/parameters.md)
  double lambda_edge = -1.0;        ///< Eq. 9; < 0 = the measured default
  /// Beyond the paper: cost of a quad turned into a triangle by a one-sided collapse;
  /// < 0 = the measured default, 0 = the paper's objective.
  double lambda_tri = -1.0;

  // --- objective (issue "Shape first"; docs/shape_objective.md) ----------------
  /// What the selection minimises (names for the CLI, manifests and Python: "shape", "paper";
  /// parse_objective below).
  ///   * Shape (default): the geometric error of the mesh it produces (cluster quadrics at the
  ///     collapse's placement, plus the quad-shape term), by a deterministic greedy
  ///     (src/select/shape_selection.h).
  ///   * Paper: Eq. 9 with the MIP / annealing search below (the paper's objective, for the
  ///     ablation table).
  enum class Objective : std::uint8_t { Shape, Paper };
  Objective objective = Objective::Shape;
  /// Quads joined again from triangle pairs before the reduction (src/mesh/quad_recovery.h;
  /// docs/scenes.md, "Triangulated inputs"; names "auto", "on", "off": parse_quad_recovery).
  /// Blender's thresholds (40°, 40°); on six fan-triangulated quad meshes 93–99 % of the quads it
  /// makes were input quads.
  ///   * Auto (default): when every face of the input is a triangle, as glTF and most exporters
  ///     write them.
  ///   * On: also for meshes with polygons (their triangles are joined where they pair up).
  ///   * Off: never.
  enum class QuadRecovery : std::uint8_t { Auto, On, Off };
  QuadRecovery recover_quads = QuadRecovery::Auto;
  double lambda_shape = -1.0;             ///< shape term weight; < 0 = the measured default
  double triangle_collapse_factor = -1.0;  ///< handicap of single collapses; < 0 = by ratio (below), 0 = none
  double max_triangle_share = -1.0;        ///< cap of their share of the reduction; < 0 = default
  int swap_rounds = -1;                    ///< exchange rounds after the shape greedy; < 0 = default
  double triangle_penalty = -1.0;          ///< handicap of segment collapses per triangle made; < 0 = by ratio
  /// Unless given, the two handicaps follow the target ratio r = N / N₀ (docs/shape_objective.md,
  /// "Quads by ratio"): at r <= aggressive_ratio factor `aggressive_factor` and penalty 0 (most
  /// of the mesh must go; triangles where they pay), at r >= mild_ratio `mild_factor` and
  /// `mild_penalty` (a mild LOD keeps its quads), linear in between.
  double aggressive_ratio = 0.4, mild_ratio = 0.6;
  double aggressive_factor = 3.0, mild_factor = 6.0;
  double mild_penalty = 1.0;
  /// > 0: the shape greedy drops moves that flip a face by more than this angle against its
  /// input face or make one degenerate (ShapeSelectionParams::check_faces); 0 = off, the default
  /// (measured worse: docs/shape_objective.md).
  double shape_flip_angle_deg = 0.0;

  // --- effort and time (issue 20) ---------------------------------------------------------------
  /// How much work to spend, > 0; 1 = the measured default. The shape objective plans `effort`
  /// times the passes (pass ratio 0.9^(1/effort), at most 32 · effort passes; an explicit
  /// pass_ratio / max_passes wins): the output depends on the input and options only. The paper
  /// objective multiplies its MIP time budget by it.
  double effort = 1.0;
  /// Shape objective: an optional upper bound on the run's wall time, seconds (0 = none, the
  /// default). Once a pass ends past it, the next pass aims at the target and is the last planned
  /// one (report: time_bound_reached); only then does the output depend on the clock.
  double time_bound_seconds = 0.0;

  // --- solver (Objective::Paper) --------------------------------------------------------------
  double time_limit_seconds = 5.0;  ///< MIP time budget (Objective::Paper); 0 = greedy selection only
  /// Threads: the shape greedy's first pricing and the collapse's face checks (the output is the
  /// same for any count), CBC and the annealing runs of the paper objective; 0 = all cores.
  int threads = 0;
  /// From this many faces on, a pass builds its vertex quadrics and feature lines on a second
  /// thread beside the analysis, and the run its input surface's BVH beside the feature lines
  /// and UV islands (speed only: the output is the same either way). Below it they take a few
  /// milliseconds together and a thread's start is not worth it; not tuned.
  Index min_faces_beside = 20000;
  std::uint32_t seed = 1;
  bool exact_formulation = false;   ///< the paper's per-edge / per-face model (slower)
  /// How the MIP budget is spent (docs/formulation.md, "Speed"; names "auto", "whole",
  /// "neighbourhoods": parse_selection_strategy), as SelectionParams::Strategy
  /// (src/select/selection.h), which the pipeline sets from it: Whole = one MIP over the whole
  /// model, Neighbourhoods = large-neighbourhood search from the greedy selection, Auto = Whole
  /// while few groups are free, else Neighbourhoods. The exact formulation always solves the whole
  /// model.
  enum class SelectionStrategy : std::uint8_t { Auto, Whole, Neighbourhoods };
  SelectionStrategy strategy = SelectionStrategy::Auto;
  /// Groups freed per neighbourhood MIP (docs/parameters.md, "Solver strategy").
  Index neighbourhood_groups = 50;
  /// A whole-model MIP stops after this many seconds without a better selection; 0 = never
  /// (SelectionParams::whole_stall_seconds, docs/formulation.md "Stopping").
  double stall_seconds = -1.0;  ///< < 0 = the measured default (default_stall_seconds())
  /// The MIP backend (names: parse_solver_backend), the one of src/ilp's backends
  /// (ilp::make_solver) of that name; CBC is the only one compiled in.
  enum class SolverBackend : std::uint8_t { Cbc };
  SolverBackend solver = SolverBackend::Cbc;

  // --- rounds (beyond the paper) ------------------------------------------------------------
  /// Selection → repair → collapse rounds: a round after the first pins the edges whose collapse
  /// was refused and re-aims the selection by the count drift (src/pipeline/simplify.cpp).
  int max_rounds = 4;
  /// Stop once the output is within this fraction of the target.
  double round_tolerance = 0.01;
  /// MIP budget of each round after the first, as a fraction of `time_limit_seconds`.
  double later_round_time_fraction = 0.25;

  // --- passes (beyond the paper) ------------------------------------------------------------
  /// A reduction below this ratio is split into passes of equal ratio, each at most this, each
  /// one run of the whole pipeline on the previous pass's output (src/pipeline/simplify.cpp);
  /// `time_limit_seconds` is shared among the planned passes. In (0, 1); < 0 = the objective's
  /// measured default: 0.9 for Shape (docs/shape_objective.md, "Passes"), 0.5 for Paper
  /// (docs/formulation.md, "Passes").
  double pass_ratio = -1.0;
  /// Most passes, the planned ones and extra ones that aim at N after a miss. 1 = one pass, the
  /// paper's single global selection. < 0 = the objective's default: 32 for Shape (0.2 at a
  /// pass ratio of 0.9 plans 16), 6 for Paper.
  int max_passes = -1;
  /// When the output misses Eq. 2's band, run the pipeline again with the greedy selection and
  /// keep the output closer to the target (report: `fallback`). Beyond the paper; off in
  /// measurements of the selection itself (bench/selection_quality).
  bool greedy_fallback = true;
  /// Decide on the positions, UVs and normals rounded to float32, the precision FBX, glTF and DCC
  /// tools store, so that an OBJ and its FBX / glb reduce alike; what does not move keeps its
  /// input values (docs/scenes.md, "One mesh, any format"). false: decide on the doubles as read.
  bool float32_decisions = true;

  // --- ablations (paper Table 2) ----------------------------------------------------------------
  bool consistency = true;   ///< Eq. 4
  bool segmentation = true;  ///< §3.2.2
  bool geometry = true;      ///< Eqs. 6–8
  bool dual_repair = true;   ///< §3.3.1

  // --- features (issue 7; docs/attributes.md) --------------------------------------------------
  /// Keep UV seams, material borders, open boundaries and hard edges: the selection never
  /// collapses an edge that would join two strict feature lines or two strict feature corners,
  /// merged vertices stay on the feature line they touch, and UVs / normals of moved vertices are
  /// recomputed per wedge. false: the paper's behaviour (features only weigh in the quadrics).
  bool features = true;
  /// How the strict lines (UV seams, material borders, open boundaries) meet a budget below what
  /// they leave room for (issue 32; docs/attributes.md, "Lines that shorten"). In both modes a
  /// line shortens (a collapse along it merges two of its vertices, junctions included, and each
  /// side keeps its UVs), a collapse across it is refused, every output line stays on its input
  /// line (within ClusterCollapseParams::feature_tolerance, eval's seams_torn rule), and a UV
  /// island too small for one output face may vanish.
  ///   * Auto: as Strict until a pass stalls short of the target; then the lines around islands
  ///     below one output face may merge through them, the bound growing ×4 per further stall
  ///     (least texture first), and parts that small may vanish; the report counts the crossings
  ///     (`seams.line_crossings`) and gives the bounds reached (`seams.crossing_island_area`,
  ///     `seams.vanishing_part_area`, and per pass).
  ///   * Strict: never; the note then says how far from the target the run stopped, and why.
  enum class SeamPolicy : std::uint8_t { Auto, Strict };
  SeamPolicy seams = SeamPolicy::Auto;
  /// SeamPolicy::Auto bends lines (below) only when the target is below this fraction of the
  /// input: issue 32 asks that no seam tear down to 0.1, and lets lines give way below it, where
  /// they alone can outnumber the budget. A LOD chain rescales it so that it refers to the chain's
  /// input, not the previous level. 0 never bends.
  double bend_lines_below_ratio = 0.1;
  /// SeamPolicy::Auto at far LODs: once every island may cross and a pass still stalls, the
  /// strict lines' tolerance (ClusterCollapseParams::feature_tolerance, 0.2 of an output edge's
  /// length, eval's seams_torn rule) doubles per further stall up to this bound, so a curved line
  /// may be cut by fewer, longer edges; eval counts those edges as torn. The report gives the
  /// tolerance reached (`seams.line_tolerance`, per pass `passes[i].line_tolerance`). A value at
  /// or below 0.2 never bends. Measured in docs/attributes.md, "Far LODs".
  double max_line_tolerance = 1.6;
  /// Dihedral angle (degrees) from which a manifold edge is a hard edge (default ϵ_θ).
  double hard_angle_deg = 60.0;
  /// Place clusters that touch hard edges (and no other feature) on the hard line, as issue 7
  /// did; false = by their quadric (ClusterCollapseParams::place_on_hard_edges, measured).
  bool place_on_hard_edges = false;
  /// Gauss–Newton steps of the final fit of the output's vertices to the input surface
  /// (fit_to_surface, src/post/surface_fit.h; docs/cluster_collapse.md, "Surface fit"): each
  /// vertex moves on the two-sided Chamfer energy, connectivity and attributes unchanged, no face
  /// turned or shrunk, no vertex left farther from the input than the Hausdorff distance the fit
  /// starts from. 0 = the collapse's placements as they are. 2 (session 15): the corpus's
  /// Chamfer at 0.4 falls by 14 % (geometric mean of the per-mesh ratios) with no mesh's
  /// Hausdorff up by more than 1 %, at the time measured in docs/cluster_collapse.md, "Cost".
  int surface_fit_iterations = 2;
  /// Weight of peak vertices in that fit (SurfaceFitParams::vertex_weight: a vertex farther from
  /// the input than every sample of its faces becomes a sample too). 0 = off. Measured on the
  /// corpus at 0.25: Hausdorff −1.4 to −4.3 %, Chamfer +2.0 to +4.5 % (docs/cluster_collapse.md,
  /// "Peak vertices"): a choice between the two, so off by default.
  double surface_fit_vertex_weight = 0.0;

  // --- skinning (issue 24; docs/skinning.md) ----------------------------------------------------
  /// With a skinned input (PolyMesh::skin): the output gets weights by projection onto the input
  /// (transfer_skin_weights, include/quadlod/skin.h), and an edge is kept by the selection when
  /// its endpoints' weight_distance() exceeds `skin_border_distance` and their dominant joints
  /// differ (and, with skin_joint_parents, are not parent and child), so no cluster merges
  /// across it. > 1 = off. 0.7 (measured on the ram walk against 0.5 and off, docs/skinning.md):
  /// most of the weight changes hands across one edge — a rigid split such as eye | head.
  double skin_border_distance = 0.7;
  /// The skeleton's parent per joint (kInvalidIndex for roots): a parent and its child then
  /// count as related and may merge across a border. Empty (the default, and the CLI's
  /// --skin-border-bones any) = any two distinct dominant joints are separated: the ram's eyes
  /// are children of its head, yet a face joining eye and head is its worst frame-by-frame error.
  std::vector<Index> skin_joint_parents;
  /// Poses the reduction is measured in (docs/skinning.md, "Error under animation"): per pose,
  /// the skinning matrix of every joint (G_j B_j⁻¹, skin.h). With a skinned input and poses, the
  /// vertex quadrics that price and place every cluster are their mean over the bind pose and
  /// these poses (src/skin/pose_quadrics.h; Mohr & Gleicher 2003), so regions the animation
  /// bends cost more to reduce; rigidly moving regions cost the same as without. Empty = the
  /// bind pose only. The CLI fills it from the rig's animations (--skin-poses).
  std::vector<std::vector<Eigen::Matrix4d>> skin_poses;

  // --- guarantees -------------------------------------------------------------------------------
  /// Bound on the distance of moved vertices from the input, relative to the bounding-box
  /// diagonal; <= 0 = no bound.
  double max_hausdorff = 0.0;

  /// Progress lines on stderr (stage, percent, elapsed).
  bool progress = false;

  // --- protected regions (issue 34; docs/protect.md, include/quadlod/protect.h) -----------------
  /// One weight per input vertex in [0, 1] (empty = none, the default): 1 = the vertex keeps its
  /// exact position and the edges between two such vertices stay; 0 < w < 1 = collapses that
  /// move it cost more; merged vertices take the largest weight of their members.
  std::vector<double> protect_weights;
  /// Where the weights come from when `protect_weights` is empty: a vertex colour channel
  /// (names "none", "color:r", "color:g", "color:b": parse_protect_channel in protect.h).
  enum class ProtectChannel : std::uint8_t { None, Red, Green, Blue };
  ProtectChannel protect_channel = ProtectChannel::None;
  /// Shape objective: a vertex of weight w adds protect_strength · w · h² · |x − p|² to its
  /// quadric (h the mean edge length, p its position): moving it by d costs like protect_strength
  /// · w times the face planes of an area h² at distance d, so collapses go elsewhere first and
  /// merged vertices are pulled toward it. < 0 = the measured default (default_protect_strength).
  double protect_strength = -1.0;
  /// Paper objective: an edge adds protect_importance · w to its importance Q(e) of Eq. 9 (1 = an
  /// average edge), w the larger weight of its endpoints. < 0 = the measured default.
  double protect_importance = -1.0;
  // --- symmetry (issue 34; docs/symmetry.md) ----------------------------------------------------
  /// Mirror-symmetric reduction about a bbox-centred axis plane. Auto: the plane among x, y, z
  /// whose mirror matches the most vertices, if it matches at least symmetry_min_matched of
  /// them; X / Y / Z: that plane, if it does; Off: none. The selection then collapses every
  /// segment and single edge together with its mirror image, each cluster is placed as the
  /// reflection of its mirror cluster (on the plane when it is its own mirror), the collapse's
  /// refusals are made symmetric, the surface fit moves pairs together, and the output's mirror
  /// pairs are exact reflections. Attributes (UVs, normals, colours, skin weights) still come
  /// from each side's own input vertices. A mesh that is not symmetric within the tolerance is
  /// reduced without symmetry, with a note (report: `symmetry`).
  enum class Symmetry : std::uint8_t { Auto, X, Y, Z, Off };
  Symmetry symmetry = Symmetry::Auto;
  /// A vertex's mirror partner lies within this fraction of the bbox diagonal of its reflection.
  double symmetry_tolerance = 1e-4;
  /// The share of vertices (paired or on the plane) a plane needs to count as a mirror plane; the
  /// unmatched rest is reduced without a mirror constraint.
  double symmetry_min_matched = 0.99;
  /// Auto only: the share of the strict feature lines' edges (UV seams, material borders,
  /// boundaries; with `features`) whose mirror edge is strict too. Below it the layout is not a
  /// mirror image, each side's lines would bind both sides, and auto reduces without symmetry
  /// (with a note); an explicit axis still mirrors. The same share of the vertices with a
  /// protect weight must have a partner of the same weight (one-sided protection binds both). 0.9: the symmetric corpus meshes have 0.97–1,
  /// a smart-UV-projected mirror model 0.45, where mirroring cost +42 % Chamfer at 0.4
  /// (docs/symmetry.md, "Attributes").
  double symmetry_min_mirrored_lines = 0.9;
  // --- blend shapes (issue 34; docs/blend_shapes.md) --------------------------------------------
  /// With blend shapes (PolyMesh::morph_targets), the output gets each shape's displacements by
  /// the skin weights' projection onto the input (transfer_morph_targets, quadlod/morph.h), and
  /// the vertex quadrics that price and place every cluster count each shape's geometry with this
  /// weight against the base's 1 (src/morph/morph_quadrics.h): a region a shape deforms keeps the
  /// resolution the shape needs. 0 = the base alone decides (the shapes are still carried). The
  /// CLI's --morph-weight; the default is measured in docs/blend_shapes.md.
  double morph_error_weight = 1.0;
};

// The choices of SimplifyOptions by name, for the CLI, manifests and Python; the names are the
// report's (`options`) too. For each enum: parse_* gives the value of a name (case-sensitive),
// nullopt for any other name; to_string the name of a value ("?" for a value outside the enum,
// which simplify() refuses); *_names every name with its value, in declaration order (so the
// CLI lists them as declared: "{shape,paper}").

/// "auto", "strict".
std::optional<SimplifyOptions::SeamPolicy> parse_seam_policy(const std::string& name);
const char* to_string(SimplifyOptions::SeamPolicy policy);
std::vector<std::pair<std::string, SimplifyOptions::SeamPolicy>> seam_policy_names();
/// "shape", "paper".
std::optional<SimplifyOptions::Objective> parse_objective(const std::string& name);
const char* to_string(SimplifyOptions::Objective objective);
std::vector<std::pair<std::string, SimplifyOptions::Objective>> objective_names();
/// "auto", "on", "off".
std::optional<SimplifyOptions::QuadRecovery> parse_quad_recovery(const std::string& name);
const char* to_string(SimplifyOptions::QuadRecovery recovery);
std::vector<std::pair<std::string, SimplifyOptions::QuadRecovery>> quad_recovery_names();
/// "auto", "whole", "neighbourhoods".
std::optional<SimplifyOptions::SelectionStrategy> parse_selection_strategy(const std::string& name);
const char* to_string(SimplifyOptions::SelectionStrategy strategy);
std::vector<std::pair<std::string, SimplifyOptions::SelectionStrategy>> selection_strategy_names();
/// "cbc".
std::optional<SimplifyOptions::SolverBackend> parse_solver_backend(const std::string& name);
const char* to_string(SimplifyOptions::SolverBackend backend);
std::vector<std::pair<std::string, SimplifyOptions::SolverBackend>> solver_backend_names();
/// Symmetry (issue 34): "auto", "x", "y", "z", "off".
std::optional<SimplifyOptions::Symmetry> parse_symmetry(const std::string& name);
const char* to_string(SimplifyOptions::Symmetry symmetry);
std::vector<std::pair<std::string, SimplifyOptions::Symmetry>> symmetry_names();

struct SimplifyResult {
  PolyMesh mesh;       ///< the reduced mesh (the input unchanged when nothing is to do)
  std::string error;   ///< non-empty: the input could not be processed (mesh is empty)
  std::string note;    ///< non-empty: the result is not what was asked for, and why
  std::uint64_t input_tri_equivalent = 0;
  std::uint64_t target = 0;
  std::uint64_t achieved = 0;  ///< tri-equivalents of `mesh`
  Index quads = 0, triangles = 0, ngons = 0;
  int rounds_used = 0;  ///< in the last pass, the selection → collapse round whose output this is
  int passes_used = 0;  ///< passes whose output was kept (1 unless the reduction was split)
  /// Everything measured on the way: per-stage seconds, analysis counts, model sizes, solver
  /// status / objective / bound / gap, repair and collapse statistics.
  nlohmann::json report;
  /// Issue 34: the protect weights of `mesh`'s vertices (each the largest of the input vertices
  /// merged into it), for a further reduction of `mesh` (LOD chains); empty when none were given.
  std::vector<double> protect_weights;
  bool ok() const { return error.empty(); }
};

/// Reduces `input` to about the target size. Never throws for bad input: `error` says what is
/// wrong ("vertex 12 (1-based) has a non-finite coordinate").
SimplifyResult simplify(const PolyMesh& input, const SimplifyOptions& options);

/// The same result as simplify(input, options), for a caller that owns a large input: the
/// float32 rounding of the decisions (SimplifyOptions::float32_decisions) is done on `input`
/// itself, whose exact values are kept aside and put back before returning, instead of on a copy
/// of the whole mesh (the 1M-face grid's peak: 1465 MiB with the copy, 1430 MiB in place).
SimplifyResult simplify_in_place(PolyMesh& input, const SimplifyOptions& options);

/// The measured defaults of λ_geo and λ_edge (see docs/parameters.md).
double default_lambda_geo();
double default_stall_seconds();
double default_lambda_edge();
double default_lambda_tri();
/// The measured defaults of the shape objective (docs/shape_objective.md).
double default_lambda_shape();
double default_max_triangle_share();
int default_swap_rounds();
/// The pass ratio and pass count an objective uses when none is given (SimplifyOptions::
/// pass_ratio, max_passes; before the shape objective's scaling by `effort`).
double default_pass_ratio(SimplifyOptions::Objective objective);
int default_max_passes(SimplifyOptions::Objective objective);
/// The measured defaults of SimplifyOptions::protect_strength / protect_importance (docs/protect.md).
double default_protect_strength();
double default_protect_importance();

}  // namespace quadlod
