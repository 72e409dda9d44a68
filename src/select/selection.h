// Global edge selection (paper §3.2, Eqs. 1–9): which input edges to keep so that the reduced
// mesh has about N triangle-equivalents, poly-chord segments are kept or collapsed as a whole,
// geometric clusters keep at least one edge, and important edges survive.
//
// Two formulations of the same problem (docs/formulation.md has the derivations):
//
//   Exact  — the paper as written: one binary x_e per edge, one binary x_f per face with the
//            edge–face consistency rows of Eq. 3, the face count N' of Eq. 1 linearised per face
//            (t_f = x_f·(Σx_e − 2), three rows), x_e = x_e' rows for every segment (Eq. 4), both
//            rows of Eq. 6 per cluster edge, Eqs. 7–8 per triangle cluster.
//   Fast   — the same optimum with far fewer rows: one binary per *edge group* (the opposing edges
//            of a segment, joined through shared non-manifold edges) instead of equality rows;
//            faces whose count is a product "group × linear rest" aggregated per owning group
//            (three rows per group instead of three per quad); only the binding side of Eq. 6;
//            Eq. 7 as x_Ct ≥ 1 − y_g per group. A greedy selection is handed to the solver as
//            its start, so a timed-out solve is never worse than greedy and never empty.
//
// Either way the result is one bit per input edge: kept (1) or collapsed (0).
//
// The stage's interface. The search (groups, greedy, local-search moves, annealing,
// recombination, select_edges()) is in src/select/, the MIP models and their solves in
// src/select/formulation.{h,cpp} and src/select/neighbourhoods.cpp (docs/architecture.md).
#pragma once

#include "ilp/solver.h"
#include "mesh/connectivity.h"
#include "quadlod/mesh.h"
#include "topology/analysis.h"

#include <cstdint>
#include <string>
#include <vector>

namespace quadlod {

enum class Formulation { Fast, Exact };

struct SelectionParams {
  /// ϵ_N of Eq. 2: N' must lie within (1 ± epsilon_n)·N. The paper's value.
  double epsilon_n = 0.03;
  /// λ_geo of Eq. 9: cost of collapsing every edge of one geometric cluster (Eq. 6), in
  /// triangle-equivalents. Default chosen by measurement (docs/parameters.md, "Edge selection:
  /// λ_geo and λ_edge"; 4 until session 9).
  double lambda_geo = 2.0;
  /// λ_edge of Eq. 9: weight of the edge-importance term Σ Q(e)·x_e, where Q(e) is the edge's
  /// quadric collapse cost divided by the mean over all edges (so 1 = an average edge).
  /// Default chosen by measurement (docs/parameters.md; 0.05 until session 9).
  double lambda_edge = 0.1;
  /// λ_tri (beyond the paper): cost of each quad whose two opposite edges are decided apart —
  /// one collapsed, one kept — which turns the quad into a triangle. Such pairs exist only
  /// across segment breakpoints (§3.2.2) and without Eq. 4. In triangle-equivalents, like the
  /// count term. 0 = the paper's objective. Default chosen by measurement (docs/parameters.md).
  double lambda_tri = 4.0;
  /// Importance values are capped at this multiple of the mean, so a few huge quadrics (long
  /// edges at sharp corners) cannot dominate the count term.
  double importance_cap = 20.0;

  Formulation formulation = Formulation::Fast;
  /// Eq. 4 on/off (the "w/o consistency" ablation: every edge decided on its own).
  bool consistency = true;
  /// Eqs. 6–8 on/off (the "w/o geometric constraints" ablation).
  bool geometry = true;
  /// Edges with more than two faces cannot be collapsed safely (the collapse would join
  /// unrelated sheets), so their groups are fixed to "kept".
  bool keep_nonmanifold_edges = true;
  /// Edges that must be kept, one entry per Connectivity edge (nonzero = keep); empty = none.
  /// The pipeline pins here the edges whose collapse the reconstruction refused in an earlier
  /// round (§3.3.2 guarantees), so the next selection collapses other chords instead. Pinning
  /// an edge keeps its whole group (Eq. 4).
  std::vector<std::uint8_t> keep_edges;
  /// Issue 34 (docs/protect.md): added to each edge's importance Q(e) (after the cap), one entry
  /// per Connectivity edge; empty = none. The pipeline passes protect_importance · w, w the larger
  /// protect weight of the edge's endpoints, so the Eq. 9 objective prefers to keep such edges.
  std::vector<double> extra_importance;

  /// The MIP solve. time_limit_seconds <= 0 skips the solver and returns the greedy selection.
  std::string solver = "cbc";
  ilp::SolveParams solve;
  /// How the greedy selection reaches the solver. false (default): as a cutoff — the solver only
  /// searches for better selections and the greedy one is the floor of the result. true: as a
  /// MIP start. Measured on the corpus at ratio 0.4 with CBC 2.10.8 (Debian 12): a MIP start
  /// crashed CBC inside CglPreProcess::postProcess on 8 of 30 meshes when the time limit cut the
  /// search (e.g. godot_squash_player_cage, 5 s), and the helper's knapsack runs found weak starts
  /// make CBC skip its feasibility pump; the cutoff gives the same floor without either problem.
  bool greedy_as_mip_start = false;

  /// How the solver's time is spent (beyond the paper; docs/formulation.md, "Speed").
  ///   Whole:          one MIP over the whole model, the greedy selection as floor.
  ///   Neighbourhoods: large-neighbourhood search — starting from the greedy selection, the MIP
  ///                   restricted to `neighbourhood_groups` adjacent groups (everything else
  ///                   fixed) is solved again and again over the mesh, keeping every
  ///                   improvement, until a full sweep improves nothing or time runs out.
  ///   Auto:           Whole when at most whole_model_groups groups are free, else Neighbourhoods.
  ///                   Measured at ratio 0.4 with a 5 s budget (docs/parameters.md): the whole
  ///                   model never improved on the greedy start on any corpus mesh, even at 2–16k
  ///                   rows, while neighbourhoods improved it on most.
  /// The exact formulation always solves the whole model (it is the paper's reference).
  enum class Strategy { Auto, Whole, Neighbourhoods };
  Strategy strategy = Strategy::Auto;
  /// Free groups per neighbourhood MIP. Measured on flightgear_c172p at 0.4, 5 s, before the
  /// annealing existed (docs/formulation.md, "Speed"): 25 and 50 reached about the same, 100–400
  /// worse (fewer neighbourhoods solved: CBC's time grows faster than the neighbourhood).
  Index neighbourhood_groups = 50;
  /// Strategy Auto solves the whole model when at most this many groups are free.
  Index whole_model_groups = 400;
  /// A whole-model MIP (the exact formulation, or strategy Whole) stops when branch-and-bound
  /// has found nothing better for this many seconds (ilp::SolveParams::stall_seconds); the
  /// result then says "stalled". Measured (docs/formulation.md, "Stopping"): in 60 s solves
  /// without a stall stop on small corpus meshes, CBC's improvements came after gaps of up to
  /// 55 s without one (bishop cage), so a shorter stall loses them (up to 9 %).
  double whole_stall_seconds = 60.0;
  /// Time limit of one neighbourhood MIP, seconds.
  double neighbourhood_time_limit = 0.1;
  /// Whether neighbourhood MIPs run in a child process like whole solves (ilp::SolveParams::
  /// isolate_process). The fork costs ~30 % of a neighbourhood's time on c172p; no CBC crash was
  /// seen on neighbourhood models (all seen crashes were whole models with a MIP start or the
  /// no-consistency ablation), so they run in-process.
  bool isolate_neighbourhoods = false;
  /// Neighbourhood MIPs as plain branch-and-bound (ilp::SolveParams::light).
  bool light_neighbourhoods = true;
  /// Budget of the flip/swap/chain/exchange local search that polishes the greedy (or annealed)
  /// start, as a fraction of the time limit (it usually converges in far less; after annealing
  /// it stops at 90 % of the time limit).
  double flip_search_time_fraction = 0.3;
  /// Pair exchanges in the local search: keep one collapsed group and collapse one kept group
  /// anywhere on the mesh as one move (docs/formulation.md, "Speed").
  bool pair_exchanges = true;
  /// Chain moves in the local search: runs of consecutive segments of a poly-chord (groups
  /// linked by λ_tri split pairs) flipped as one move (docs/formulation.md, "Speed").
  bool chain_moves = true;
  /// Compound moves (ejection chains) in the local search and the annealing: flip one group,
  /// then flip nearby groups the other way, cheapest per triangle-equivalent first, until N' is
  /// back — e.g. keep one group of an emptied Eq. 6 cluster and collapse small groups around it
  /// (docs/formulation.md, "Speed").
  bool compound_moves = true;
  /// Candidates of one compound move: groups of the other value met by a breadth-first walk over
  /// groups that share a face from the seed.
  Index compound_candidates = 32;
  /// Share of the annealing's moves that are compound moves. Off: each costs ~10–50 single moves,
  /// and on flightgear_c172p at 0.4, 5 s, shares of 0.02–0.1 were no better than none (single
  /// runs within the ±100 noise of the load; docs/formulation.md, "Speed").
  double anneal_compound_share = 0.0;
  /// Simulated annealing from the greedy start, before the local search (fast formulation, a
  /// time limit > 0, greedy in the band): it runs until this fraction of the time limit has
  /// passed since select_edges() began, its temperature falling from anneal_t0 to anneal_t1
  /// (Eq. 9 units; one emptied Eq. 6 cluster costs λ_geo = 4); 0 = off. t0 measured on c172p
  /// (docs/formulation.md, "Speed"). Wall-clock driven, so the result depends on the load.
  /// 0.9 and descent_end_fraction 0.97: at 5 s on c172p and cg57 the neighbourhood MIPs after
  /// the descent gained < 1 in Eq. 9 (1–7 improving of 1–26), the annealing's moves are what
  /// counts (docs/formulation.md, "Speed"). A long budget is not affected: the annealing then ends
  /// by its move count (c172p at 180 s: after 41 s).
  double anneal_time_fraction = 0.9;
  /// Where the greedy selection misses Eq. 2's band (the hard constraints stopped it short),
  /// the fast formulation first anneals on Eq. 9 plus reach_band_penalty per triangle-equivalent
  /// outside the band, one run per thread, for up to this fraction of the time limit; the state
  /// nearest the band (then the lowest Eq. 9) is the start of everything after it. 0: the greedy
  /// selection is kept (docs/formulation.md, "Targets the greedy misses").
  /// The penalty ρ and the starting temperature of that annealing (it falls to anneal_t1): on
  /// tpsdemo_door_reactor at 0.4 (greedy 4 200 for N = 3 768, band ≤ 3 881) ρ = 8 with t0 = 128
  /// reaches the band (3 881) on every seed tried; ρ = 1 – 32 with Eq. 9's t0 = 8 end at
  /// 3 894 – 4 200, and ρ = 32 reaches it with t0 = 128 (with t0 = 32 only at 5 000 moves per
  /// group) (docs/formulation.md, "Targets the greedy misses").
  double reach_time_fraction = 0.25;
  double reach_band_penalty = 8.0;
  double reach_t0 = 128.0;
  /// After annealing, the descent runs until this fraction of the time limit has passed.
  double descent_end_fraction = 0.97;
  /// Recombination of independent parts (docs/formulation.md, "Speed"; fast formulation, after
  /// annealing): the free groups fall into components coupled only by the count row; priced
  /// descents (Eq. 9 with the count term replaced by μ N', one per price) offer each component
  /// alternatives, and a dynamic programme over N' − N picks the combination with the lowest
  /// Eq. 9 in Eq. 2's band; then the descent runs again. It takes recombination_fraction of the
  /// time limit from the end of the first descent's share (0 = off), for up to
  /// recombination_rounds rounds (a round that gains nothing ends it), each priced descent up to
  /// recombination_passes passes. The prices are offsets from the count term's slope at the
  /// incumbent (0 at N' = N, ±1 near the band's edges). Measured at 0.4, 5 s: the round gains
  /// 50–80 on c172p (0.1–0.2 s) and 270–380 on cg57 (0.25 s; prices 0.25–0.75 without the slope
  /// found nothing there, and 4 passes per price did not fit in 0.35 s).
  double recombination_fraction = 0.07;
  Index recombination_rounds = 1;
  int recombination_passes = 2;
  std::vector<double> recombination_prices = {0.0, 0.25, 0.5, 0.75, 1.0};
  double anneal_t0 = 8.0;
  double anneal_t1 = 0.05;
  /// The annealing also ends after this many moves per free group (small meshes).
  double anneal_moves_per_group = 1000.0;
  /// Penalty continuation in the annealing (docs/formulation.md, "Speed"): until anneal_ramp_start
  /// of its schedule the count term |N' − N| of Eq. 9 weighs anneal_count_weight (1 = as in Eq. 9)
  /// and N' may leave Eq. 2's band by anneal_band_relax × ϵ_N N; from anneal_ramp_start to
  /// anneal_ramp_end both go linearly back to Eq. 9 and the hard band (the excess beyond the band
  /// costs anneal_band_penalty × the ramp's progress per triangle-equivalent); after that, a count
  /// outside the band may only move toward it. Only selections in the band are kept as the best.
  /// With the true objective all the way (weight 1, relax 0), the count term's slope and the hard
  /// band edge block most moves once N' sits on N (c172p) or on the band's edge (cg57).
  /// Measured at 0.4, 5 s (single runs, load ~5): c172p 2 200–2 400 → 1 740–1 920, cg57
  /// 95 200–98 300 → 94 300–94 500.
  double anneal_count_weight = 0.25;
  double anneal_band_relax = 1.0;
  double anneal_band_penalty = 4.0;
  double anneal_ramp_start = 0.6;
  double anneal_ramp_end = 0.95;
  /// Where the annealing's schedule ends by its move count (small meshes) within half its time,
  /// also run it on Eq. 9 throughout (count weight 1, no band relaxation) from the same start and
  /// keep the lower Eq. 9: on short schedules the continuation can end above the plain annealing
  /// (docs/formulation.md, "Speed").
  bool anneal_plain_when_short = true;
  /// Annealing runs per thread (docs/formulation.md, "Speed"), one after the other from the same
  /// start, each an equal share of the thread's time left; more run while at least half the last
  /// run's time is left, up to anneal_max_runs per thread. The best run is the incumbent; up to
  /// anneal_max_alternatives others are offered to the recombination, which may take each
  /// independent component from any of them.
  int anneal_runs = 2;
  /// Priced runs (docs/formulation.md, "Speed"): where the runs are recombined, every thread's
  /// second, fourth, … run anneals cost + μ N' (Eq. 9 with the count term replaced by a price μ
  /// per triangle-equivalent) for μ = the count term's slope at the thread's first run (0, or ±1
  /// near the band's edges) plus the next of these offsets (mirrored below the band), and is
  /// only an alternative for the recombination. Empty = no priced runs. Since λ_geo 2 and
  /// λ_edge 0.1, c172p's components at 0.4 add up to N between μ = 0.25 and 0.3; 0.25, 0.3
  /// gave lower Eq. 9 at 5 s than 0.25, 0.4 and than 0.2, 0.3 (docs/formulation.md, "Priced runs
  /// by component").
  std::vector<double> anneal_prices = {0.25, 0.3, 0.2, 0.35};
  /// A priced run anneals each independent component on its own (docs/formulation.md, "Priced
  /// runs by component"): every component gets two runs of priced_moves_per_group moves per
  /// group, then the components whose two runs ended apart get two runs of priced_moves_factor
  /// times as many, and so on (up to priced_moves_per_group_max), while the run's time lasts and
  /// it has made fewer moves than a whole-mesh schedule (anneal_moves_per_group per free group);
  /// each component keeps its best state. The run starts from the thread's first (plain) run.
  /// false = one annealing of the whole mesh per priced run, from the start. Start effort 200
  /// against 100 measured on c172p at 0.4, 5 s; the factor 4 and the cap 6 400 are not tuned.
  bool priced_by_component = true;
  double priced_moves_per_group = 200.0;
  double priced_moves_factor = 4.0;
  double priced_moves_per_group_max = 6400.0;
  /// anneal_runs applies only when no independent component holds more than this share of the
  /// free groups; otherwise one run per thread (plus the extra ones).
  double anneal_runs_max_share = 0.5;
  /// Caps, not tuned: without them a small mesh with a long budget would run a schedule of
  /// milliseconds thousands of times, and keep every result (c172p at 180 s ran 29 runs on 2
  /// threads; an alternative costs one byte per group).
  int anneal_max_runs = 32;
  std::size_t anneal_max_alternatives = 64;
  bool quiet = true;  ///< progress lines on stderr when false
};

/// Sizes of the model as built, for reports.
struct SelectionModelStats {
  Index edge_groups = 0;         ///< decision units (fast) or edges (exact)
  Index fixed_kept_groups = 0;   ///< groups fixed to 1 (non-manifold edges)
  Index owner_aggregates = 0;    ///< fast: groups that carry aggregated face terms
  Index general_faces = 0;       ///< faces needing their own x_f / t_f
  Index triangle_faces = 0;      ///< triangles with their own AND variable
  Index linear_faces = 0;        ///< faces whose count is linear in one group
  Index geo_clusters = 0;        ///< Eq. 6 clusters in the model
  Index tri_clusters = 0;        ///< Eq. 7 clusters
  Index tri_neighbour_rows = 0;  ///< Eq. 8 rows
  Index split_pairs = 0;         ///< λ_tri terms (opposite quad edges in different units)
  ilp::ModelSize size;
};

struct SelectionResult {
  /// One entry per Connectivity edge: 1 kept, 0 collapsed. Always filled (all 1 when there is
  /// nothing to do).
  std::vector<std::uint8_t> edge_kept;

  std::uint64_t input_tri_equivalent = 0;
  std::uint64_t target = 0;             ///< N (tri-equivalents)
  std::uint64_t predicted = 0;          ///< N' of the selection (Eq. 1, exact for the bits)
  std::uint64_t greedy_predicted = 0;   ///< N' of the greedy start
  double objective = 0.0;               ///< Eq. 9 value of the selection
  double greedy_objective = 0.0;        ///< Eq. 9 value of the greedy start
  /// Eq. 9 without the count term when every edge is kept (−λ_edge Σ Q). objective − baseline
  /// is the selection's cost above "keep everything", >= 0 up to the count term: the quantity to
  /// compare relatively (the objective itself is offset by this constant).
  double baseline_objective = 0.0;
  Index collapsed_groups = 0;
  Index collapsed_clusters = 0;         ///< Eq. 6 clusters with every edge collapsed
  bool band_enforced = false;           ///< Eq. 2 was a hard constraint (else unreachable)
  /// Empty, or why the selection is not what was asked for ("target at or above the input
  /// size: nothing to do", "out of reach of the hard constraints" where the solver proved it,
  /// "no selection within 3 % ... was found" otherwise, each with the closest count).
  std::string note;

  bool solver_ran = false;
  ilp::SolveResult solve;               ///< statistics (solution vector dropped)
  std::string strategy;                 ///< "whole", "neighbourhoods" or "greedy"
  Index neighbourhoods = 0;             ///< neighbourhood MIPs solved
  Index neighbourhoods_improved = 0;    ///< of those, how many improved the selection
  Index neighbourhood_sweeps = 0;       ///< full passes over the groups
  bool neighbourhoods_converged = false;  ///< a full sweep improved nothing
  double seconds_neighbourhood_build = 0.0;  ///< building the neighbourhood models
  double flip_search_objective = 0.0;   ///< Eq. 9 after annealing and the local search (the MIPs' start)
  Index flip_passes = 0, flips = 0, swaps = 0, exchanges = 0, chains = 0;
  Index compounds = 0;                  ///< compound moves taken by the descent
  std::int64_t anneal_compounds = 0;    ///< compound moves accepted by the annealing
  double seconds_flip_search = 0.0;
  std::int64_t anneal_moves = 0, anneal_accepted = 0;  ///< simulated annealing moves tried / taken
  double seconds_anneal = 0.0;
  int anneal_runs = 0;                  ///< annealing runs, over all threads
  int anneal_priced_runs = 0;           ///< of which priced (SelectionParams::anneal_prices)
  std::int64_t priced_component_runs = 0;  ///< component annealings of the priced runs (priced_by_component)
  bool reach_ran = false;               ///< the greedy missed the band and reach_band searched for it
  std::int64_t reach_moves = 0;         ///< annealing moves of that search
  std::uint64_t reach_predicted = 0;    ///< N' of its state nearest the band
  double seconds_reach = 0.0;
  Index components = 0;                 ///< independent parts (components of the free groups)
  Index largest_component = 0;          ///< free groups in the largest of them
  Index recombination_rounds = 0, recombination_improved = 0, recombination_moved = 0;
  double seconds_recombination = 0.0;
  double recombination_gain = 0.0;      ///< Eq. 9 lowered by the recombination (before the second descent)
  SelectionModelStats model;
  /// Why the selection stopped (docs/formulation.md, "Speed"): "nothing to do", "greedy" (no
  /// time limit), "band not reached" (neither the greedy, nor reach_band, nor a whole-model
  /// MIP where the model is small found a selection in Eq. 2's band: the nearest is kept), "optimal" (whole-model MIP proven optimal), "converged" (the neighbourhood
  /// search finished two sweeps without an improvement), "stalled" (whole-model MIP without an
  /// improvement for SelectionParams::whole_stall_seconds), "time" (the time limit).
  std::string stop_reason;
  bool anneal_converged = false;        ///< the annealing schedule ended before the time did
  bool flip_search_converged = false;   ///< the descent ended in a local optimum
  /// Importance, groups, constraints, face terms and group adjacency.
  double seconds_prepare = 0.0;
  double seconds_build = 0.0;
  double seconds_greedy = 0.0;
  double seconds_solve = 0.0;
};

/// Selects the edges to keep for a reduction to `target` triangle-equivalents.
/// `analysis` must come from analyze() on the same mesh and connectivity (its segmentation and
/// clustering parameters decide the segments and clusters used here).
SelectionResult select_edges(const PolyMesh& mesh, const Connectivity& conn,
                             const AnalysisResult& analysis, std::uint64_t target,
                             const SelectionParams& params = {});

/// Q(e) of Eq. 9 for every edge: the quadric error (Garland–Heckbert, area-weighted face planes
/// summed at both endpoints) of collapsing the edge to the best point on it, divided by the
/// mean over all edges with a positive error and capped at `cap`. All zero on a flat mesh.
std::vector<double> edge_importance(const PolyMesh& mesh, const Connectivity& conn, double cap);
/// edge_importance() plus params.extra_importance (issue 34), what the selection prices.
std::vector<double> selection_importance(const PolyMesh& mesh, const Connectivity& conn, const SelectionParams& params);

/// N' of Eq. 1 for a given edge selection: Σ_f max(0, kept edges of f − 2). This is the count
/// the ILP optimises; the mesh produced by the collapse may differ slightly (see §3.3).
std::uint64_t predicted_tri_equivalent(const PolyMesh& mesh, const Connectivity& conn,
                                       const std::vector<std::uint8_t>& edge_kept);

/// Quads with exactly three kept edges under a selection: the triangles it creates (for
/// reports; the collapse may still refuse some of them).
std::uint64_t predicted_new_triangles(const PolyMesh& mesh, const Connectivity& conn,
                                      const std::vector<std::uint8_t>& edge_kept);

/// Internals exposed for tests (tests/test_formulation.cpp); not part of the stage's interface.
namespace detail {

/// The fast model of one neighbourhood of the large-neighbourhood search around the selection
/// `edge_kept` (one bit per edge, uniform per group), with the groups of `free_edges` free and
/// every other group fixed, built by scanning every face and cluster (indexed = false) or
/// through the per-group index the search uses (true); fixed columns substituted out
/// (ilp::without_fixed_columns). Both must give the same model up to the objective offset.
ilp::Model neighbourhood_model(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                               std::uint64_t target, const SelectionParams& params,
                               const std::vector<std::uint8_t>& edge_kept, const std::vector<Index>& free_edges,
                               bool indexed);

/// The local search of select_edges() from the selection `edge_kept` (uniform per group, N' in
/// Eq. 2's band): simulated annealing (if params.anneal_time_fraction > 0) for up to `seconds`,
/// then the flip/swap/chain/exchange descent for up to `seconds`; returns the edge bits it ends at.
std::vector<std::uint8_t> local_search(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                       std::uint64_t target, const SelectionParams& params,
                                       const std::vector<std::uint8_t>& edge_kept, double seconds);

/// One priced annealing run (SelectionParams::anneal_prices) from the selection `edge_kept`
/// (uniform per group, Eq. 8 kept): annealing on cost + price × N' (Eq. 9 with the count term
/// replaced by the price; no band) for params.anneal_moves_per_group moves per free group or
/// `seconds`, whichever ends first; returns the edge bits of the lowest value it met.
std::vector<std::uint8_t> priced_anneal(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                        std::uint64_t target, const SelectionParams& params,
                                        const std::vector<std::uint8_t>& edge_kept, double price, double seconds);

/// One priced run by component (SelectionParams::priced_by_component) from the selection
/// `edge_kept` (uniform per group, Eq. 8 kept): every independent component annealed on its own
/// on cost + price × N', in rounds of growing effort, for up to `seconds`; returns the edge bits
/// of every component's best state.
std::vector<std::uint8_t> priced_component_anneal(const PolyMesh& mesh, const Connectivity& conn,
                                                  const AnalysisResult& analysis, const SelectionParams& params,
                                                  const std::vector<std::uint8_t>& edge_kept, double price,
                                                  double seconds);

/// The search for Eq. 2's band that follows a greedy selection outside it
/// (SelectionParams::reach_time_fraction), from the selection `edge_kept` (uniform per group,
/// Eq. 8 kept), on params.solve.threads threads: returns the edge bits of the state nearest the
/// band, then lowest in Eq. 9.
std::vector<std::uint8_t> reach_band(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                     std::uint64_t target, const SelectionParams& params,
                                     const std::vector<std::uint8_t>& edge_kept, double seconds);

/// The recombination of independent parts of select_edges() alone (no annealing, no descent),
/// from the selection `edge_kept` (uniform per group, N' in Eq. 2's band), for
/// params.recombination_rounds rounds or until a round gains nothing; returns the edge bits it
/// ends at. `components`, if given, receives the number of independent parts. `alternatives`
/// (edge bits, uniform per group, as other annealing runs give) are offered besides the priced
/// descents' end states.
std::vector<std::uint8_t> recombine(const PolyMesh& mesh, const Connectivity& conn, const AnalysisResult& analysis,
                                    std::uint64_t target, const SelectionParams& params,
                                    const std::vector<std::uint8_t>& edge_kept, Index* components = nullptr,
                                    const std::vector<std::vector<std::uint8_t>>& alternatives = {});

}  // namespace detail

}  // namespace quadlod
