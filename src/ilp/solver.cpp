// quadlod — backend registry and the finishing steps every backend shares (see solver.h).
#include "ilp/solver.h"

#include <algorithm>
#include <cmath>
#include <thread>

namespace quadlod::ilp {

namespace {

struct Backend {
  std::string_view name;
  std::unique_ptr<Solver> (*make)();
};

// The compiled-in backends, in preference order. An explicit table rather than self-registering
// static objects: quadlod is a static library, and the linker drops object files nobody
// references, so a backend that only registers itself from a static initialiser would silently
// vanish from the binary.
constexpr Backend kBackends[] = {
    {"cbc", &make_cbc_solver},
};

}  // namespace

std::vector<std::string> available_solvers() {
  std::vector<std::string> names;
  for (const Backend& b : kBackends) names.emplace_back(b.name);
  return names;
}

std::unique_ptr<Solver> make_solver(std::string_view name, std::string* error) {
  for (const Backend& b : kBackends)
    if (b.name == name) return b.make();
  if (error) {
    std::string list;
    for (const Backend& b : kBackends) list += (list.empty() ? "" : ", ") + std::string(b.name);
    *error = "unknown ILP solver '" + std::string(name) + "' (available: " + list + ")";
  }
  return nullptr;
}

std::string_view to_string(SolveStatus s) {
  switch (s) {
    case SolveStatus::Optimal: return "optimal";
    case SolveStatus::Feasible: return "feasible";
    case SolveStatus::Infeasible: return "infeasible";
    case SolveStatus::Unbounded: return "unbounded";
    case SolveStatus::NoSolution: return "no-solution";
    case SolveStatus::Error: return "error";
  }
  return "?";
}

std::string_view to_string(CallStatus s) {
  switch (s) {
    case CallStatus::Ok: return "ok";
    case CallStatus::Warning: return "warning";
    case CallStatus::Error: return "error";
  }
  return "?";
}

std::string_view to_string(StartStatus s) {
  switch (s) {
    case StartStatus::NotGiven: return "not-given";
    case StartStatus::WrongSize: return "wrong-size";
    case StartStatus::Accepted: return "accepted";
    case StartStatus::Rejected: return "rejected";
    case StartStatus::Unknown: return "unknown";
    case StartStatus::NotUsed: return "not-used";
  }
  return "?";
}

namespace backend {

std::string check_params(const SolveParams& p) {
  if (!(p.time_limit_seconds > 0.0))  // also rejects NaN
    return "time_limit_seconds must be > 0 (kInf for no limit)";
  if (p.threads < 0) return "threads must be >= 0 (0 = hardware concurrency)";
  if (!(p.relative_gap >= 0.0) || std::isinf(p.relative_gap)) return "relative_gap must be finite and >= 0";
  if (!(p.feasibility_tolerance >= 0.0) || std::isinf(p.feasibility_tolerance))
    return "feasibility_tolerance must be finite and >= 0";
  if (p.log_level < 0) return "log_level must be >= 0";
  if (!(p.stall_seconds > 0.0)) return "stall_seconds must be > 0 (kInf = never)";
  return {};
}

int resolve_threads(const SolveParams& p) {
  if (p.threads > 0) return p.threads;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

void note(SolveResult& r, CallStatus level, const std::string& line) {
  if (!r.message.empty()) r.message += "; ";
  r.message += line;
  if (static_cast<int>(level) > static_cast<int>(r.call)) r.call = level;
}

void finish(const Model& model, const SolveParams& params, SolveResult& r) {
  const double tol = params.feasibility_tolerance;
  r.built = model.size();

  // 1–2. Snap and re-check the backend's candidate. Backends return integer columns as doubles
  // within their integrality tolerance (0.9999999...); downstream code reads bits, so we hand out
  // exact integers, and only if the snapped point still satisfies every row.
  if (!r.solution.empty()) {
    std::vector<double> snapped = r.solution;
    if (snapped.size() == model.num_cols())
      for (Col c = 0; c < model.num_cols(); ++c)
        if (model.is_integer(c) && std::abs(snapped[c] - std::round(snapped[c])) <= tol)
          snapped[c] = std::round(snapped[c]);
    const double v_snapped = model.max_violation(snapped);
    const double v_raw = model.max_violation(r.solution);
    if (v_snapped <= tol) {
      r.solution = std::move(snapped);
    } else if (v_raw <= tol) {
      // keep the raw point: snapping pushed a row over the tolerance
    } else {
      note(r, CallStatus::Warning,
           "discarded the backend's solution: " + model.describe_violation(r.solution, tol));
      r.solution.clear();
      if (r.status == SolveStatus::Optimal || r.status == SolveStatus::Feasible)
        r.status = SolveStatus::Error;
    }
  }

  // 3. The initial solution as a floor: a solve is never worse than its start.
  const std::vector<double>& start = model.initial_solution();
  if (!start.empty() && start.size() == model.num_cols()) {
    r.start_feasible = model.is_feasible(start, tol);
    if (r.start_feasible) {
      const double start_obj = model.evaluate(start);
      const bool better = r.solution.empty() ||
                          start_obj < model.evaluate(r.solution) - 1e-9 * std::max(1.0, std::abs(start_obj));
      if (better) {
        const bool had_candidate = !r.solution.empty();
        r.solution = start;
        r.solution_is_start = true;
        switch (r.status) {
          case SolveStatus::Optimal:
            // "Optimal" means optimal within relative_gap, so a start that beats the candidate by
            // less than that is optimal too. Beating it by more is a backend bug: do not repeat
            // its claim.
            if (had_candidate && start_obj < r.best_bound - params.relative_gap * std::max(
                                                                 {std::abs(start_obj), std::abs(r.best_bound), 1e-9})) {
              r.status = SolveStatus::Feasible;
              note(r, CallStatus::Warning, "backend claimed optimality but the initial solution is better");
            }
            break;
          case SolveStatus::Feasible: break;
          case SolveStatus::Infeasible:
            note(r, CallStatus::Warning, "backend claimed infeasibility but the initial solution is feasible");
            r.status = SolveStatus::Feasible;
            break;
          case SolveStatus::Unbounded:
            note(r, CallStatus::Warning, "LP relaxation unbounded; returning the feasible initial solution");
            r.status = SolveStatus::Feasible;
            break;
          case SolveStatus::NoSolution:
          case SolveStatus::Error: r.status = SolveStatus::Feasible; break;
        }
      }
    }
  }
  if (!r.solution.empty() && r.status != SolveStatus::Optimal) r.status = SolveStatus::Feasible;
  if (r.solution.empty() &&
      (r.status == SolveStatus::Optimal || r.status == SolveStatus::Feasible))
    r.status = SolveStatus::Error;

  // 4. Numbers.
  if (r.status == SolveStatus::Infeasible) r.best_bound = kInf;
  if (r.solution.empty()) {
    r.objective = kInf;
    r.max_violation = kInf;
    r.gap = kInf;
    return;
  }
  r.objective = model.evaluate(r.solution);
  r.max_violation = model.max_violation(r.solution);
  if (std::isnan(r.best_bound)) r.best_bound = -kInf;
  // A lower bound above a feasible objective is numerical noise of the backend.
  r.best_bound = std::min(r.best_bound, r.objective);
  if (r.status == SolveStatus::Optimal && r.best_bound == -kInf) r.best_bound = r.objective;
  if (!std::isfinite(r.best_bound)) {
    r.gap = kInf;
  } else {
    const double denom = std::max({std::abs(r.objective), std::abs(r.best_bound), 1e-9});
    r.gap = std::max(0.0, (r.objective - r.best_bound) / denom);
  }
}

}  // namespace backend

}  // namespace quadlod::ilp
