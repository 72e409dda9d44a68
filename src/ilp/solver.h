// quadlod — MIP backend interface: parameters, result, factory by name.
//
// A backend turns a solver-neutral ilp::Model into a SolveResult. It never changes the model.
// Adding a backend (HiGHS, CP-SAT, ...) is one new file implementing `Solver` plus one line in the
// table of src/ilp/solver.cpp; no formulation code changes.
//
// Two statuses, as in HiGHS (HighsStatus vs HighsModelStatus):
//   * `call`   — did the backend run cleanly (Ok), with something worth reading in `message`
//                (Warning), or fail (Error)?
//   * `status` — what is known about the model: Optimal, Feasible, Infeasible, Unbounded,
//                NoSolution (limit reached without an incumbent) or Error (nothing is known).
// Guarantee shared by every backend: if the model carries an initial solution that is feasible
// (Model::is_feasible with SolveParams::feasibility_tolerance), the result carries a solution that
// is at least as good, whatever the solver did (time limit, crash, bogus infeasibility claim).
// Every returned solution has been re-checked against the model by the backend.
#pragma once

#include "ilp/model.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace quadlod::ilp {

/// What a backend reports when its incumbent improves (for CLI progress on stderr).
struct Progress {
  double objective = kInf;    ///< new incumbent objective (offset included)
  double best_bound = -kInf;  ///< proven lower bound at that moment (offset included)
  double seconds = 0.0;       ///< wall-clock seconds since solve() was entered
};

struct SolveParams {
  /// Wall-clock budget of the whole solve() call in seconds, > 0; kInf = no limit. Counted from
  /// entry, so it includes converting the model and waiting for another CBC solve of this
  /// process to finish (CBC runs are serialised). The backend's clock checks are coarse: on a
  /// 300k-row, 1.45M-nonzero model a 10 s and a 30 s budget returned after 11.0 s and 31.0 s.
  double time_limit_seconds = 5.0;
  /// Worker threads, >= 0; 0 = std::thread::hardware_concurrency(). The CBC backend runs its
  /// tree search in deterministic parallel mode, so for a fixed seed the search is repeatable
  /// up to where the time limit cuts it.
  int threads = 1;
  /// Random seed for the backend's heuristics; the same seed gives the same search.
  std::uint32_t seed = 1;
  /// Stop when gap (see SolveResult::gap) <= this, >= 0.
  double relative_gap = 1e-4;
  /// Stop when branch-and-bound has gone this many wall-clock seconds without a better
  /// incumbent (counted from the start of branch-and-bound or from the last improvement), > 0;
  /// kInf = never. The result is then Feasible with `stalled` set. For searches that will not
  /// close their gap in the budget (src/select/formulation.cpp: whole-model selections), so that a
  /// solve which has stopped finding anything does not sit out the whole time limit.
  double stall_seconds = kInf;
  /// Tolerance of the re-check every solution goes through (Model::max_violation, absolute).
  double feasibility_tolerance = 1e-6;
  /// Whether the model's initial solution is handed to the backend as a MIP start (true) or
  /// only used as the floor of the result (false; the guarantee above holds either way).
  /// Trade-off seen with CBC: an incumbent from the start makes it skip its feasibility pump, so
  /// a weak start can end worse than no start. On random 300-item, 40-row 0/1 knapsacks with a
  /// greedy start, 1 s and 3 s solves ended 0.2-2.6 % worse with the start than without it in
  /// 12 of 12 runs. A good start (e.g. a previous solution) helps through its cutoff.
  bool start_as_mip_start = true;
  /// Plain branch-and-bound: no cut generation, no primal heuristics, no pre-processing. For
  /// many small MIPs with a good start (the neighbourhoods of src/select/neighbourhoods.cpp), where
  /// those stages cost more than the search (CBC: ~70 ms per call on a 100-group neighbourhood).
  bool light = false;
  /// Run the backend in a child process (POSIX fork; the CBC backend). A crash inside the solver
  /// library — seen with Debian's CBC 2.10.8: SIGSEGV in CglPreProcess::postProcess, SIGABRT on
  /// a Clp assertion — then ends only that child: the solve reports "no solution" with a warning
  /// and the initial solution, if any, is the result. A child that overruns the time limit by
  /// more than max(2 s, 25 %) is killed. Progress callbacks still run in the caller's process.
  bool isolate_process = true;
  /// 0 = silent; >= 1 passes the level to the backend's own log (CBC: its log level, written
  /// to stdout by CBC itself).
  int log_level = 0;
  /// Called (serialised, from solver threads) whenever the incumbent improves. Must not throw
  /// and must not start another solve (CBC runs are serialised: it would deadlock).
  std::function<void(const Progress&)> on_progress;
};

enum class CallStatus { Ok, Warning, Error };

enum class SolveStatus {
  Optimal,     ///< solution proven optimal within relative_gap
  Feasible,    ///< solution present, optimality not proven (time limit, or see `message`)
  Infeasible,  ///< proven infeasible (no solution)
  Unbounded,   ///< LP relaxation unbounded (no solution); the MIP may also be infeasible
  NoSolution,  ///< limit reached before any solution was found
  Error,       ///< the backend failed and nothing is known (no solution)
};

enum class StartStatus {
  NotGiven,   ///< the model carries no initial solution
  WrongSize,  ///< initial solution size != num_cols(); ignored
  Accepted,   ///< the backend took it as its first incumbent
  Rejected,   ///< the backend could not use it (infeasible for the backend)
  Unknown,    ///< the backend stopped before it looked at the start
  NotUsed,    ///< not handed to the backend (SolveParams::start_as_mip_start == false)
};

struct SolveResult {
  CallStatus call = CallStatus::Error;
  SolveStatus status = SolveStatus::Error;
  /// Empty when call == Ok; otherwise one line saying what happened.
  std::string message;
  std::string backend;  ///< Solver::name() of the backend that produced this

  /// The solution (num_cols() values; integer columns exactly integral) or empty when
  /// status is Infeasible / Unbounded / NoSolution / Error.
  std::vector<double> solution;
  double objective = kInf;    ///< Model::evaluate(solution); kInf without a solution
  double best_bound = -kInf;  ///< proven lower bound on the optimum (offset included)
  /// Relative gap  (objective - best_bound) / max(|objective|, |best_bound|, 1e-9), clamped to
  /// [0, inf); kInf without a solution or without a finite bound; 0 when both are equal.
  /// This is CBC's "ratioGap" measure, so SolveParams::relative_gap means the same thing.
  double gap = kInf;
  double max_violation = kInf;  ///< Model::max_violation(solution); kInf without a solution
  double seconds = 0.0;         ///< wall-clock time of the whole solve() call
  std::int64_t nodes = 0;       ///< branch-and-bound nodes
  std::int64_t iterations = 0;  ///< LP (simplex) iterations
  /// The search was stopped by SolveParams::stall_seconds (not by the time limit).
  bool stalled = false;
  /// Wall-clock seconds from entry to the last improvement of the incumbent (0 = none found:
  /// the start, if any, stood).
  double seconds_to_best = 0.0;
  /// Wall-clock seconds from entry to the start of branch-and-bound (0 = never reached: root
  /// LP cut short, or the problem settled before it).
  double seconds_to_search = 0.0;

  ModelSize built;      ///< the model as handed to the backend
  /// The model that entered branch-and-bound, i.e. after the backend's pre-processing (CBC skips
  /// pre-processing when the time limit is already used up; then this equals `built`). Fields
  /// are -1 when not known (no branch-and-bound: pure LPs, root LP cut short, pre-processing
  /// ended the solve).
  ModelSize presolved;

  StartStatus start = StartStatus::NotGiven;
  bool start_feasible = false;     ///< the initial solution passed Model::is_feasible
  bool solution_is_start = false;  ///< the returned solution is the initial solution

  bool has_solution() const { return !solution.empty(); }
};

class Solver {
 public:
  virtual ~Solver() = default;
  /// Solves `model` (minimisation). Never throws; every failure is reported in the result.
  /// Invalid parameters give call = Error, status = Error (plus the start, if feasible).
  virtual SolveResult solve(const Model& model, const SolveParams& params) = 0;
  /// The name make_solver() knows this backend by ("cbc").
  virtual std::string name() const = 0;
};

/// Names of the compiled-in backends, in preference order.
std::vector<std::string> available_solvers();

/// The backend called `name` (case-sensitive), or nullptr if there is none; then `*error` (if
/// given) says "unknown ILP solver 'x' (available: cbc)".
std::unique_ptr<Solver> make_solver(std::string_view name, std::string* error = nullptr);

/// Factories of the compiled-in backends (one per backend file).
std::unique_ptr<Solver> make_cbc_solver();

/// Shared steps for backend implementations, so that every backend gives the guarantees above.
namespace backend {

/// "" if the parameters are valid, otherwise what is wrong with them.
std::string check_params(const SolveParams& params);

/// Threads to actually use: params.threads, or the hardware concurrency (>= 1) for 0.
int resolve_threads(const SolveParams& params);

/// Finishes a result whose `status`, `solution` (the backend's candidate, possibly empty),
/// `best_bound`, `call` and `message` the backend has filled:
///   1. integer columns within feasibility_tolerance of an integer are snapped to it;
///   2. the candidate is re-checked (Model::max_violation); one that fails is dropped with a
///      Warning (status becomes Error if nothing replaces it);
///   3. a feasible initial solution replaces a missing or worse candidate (solution_is_start);
///      statuses that contradict it (Infeasible, Unbounded, NoSolution, Error) become Feasible;
///   4. objective, max_violation, gap, start_feasible and `built` are filled in.
void finish(const Model& model, const SolveParams& params, SolveResult& result);

/// Appends `line` to result.message ("; "-separated) and raises call to at least `level`.
void note(SolveResult& result, CallStatus level, const std::string& line);

}  // namespace backend

/// Names for printing: "optimal", "feasible", ...
std::string_view to_string(SolveStatus status);
std::string_view to_string(CallStatus status);
std::string_view to_string(StartStatus status);

}  // namespace quadlod::ilp
