// quadlod — COIN-OR CBC backend for ilp::Model (the only file that includes COIN headers).
//
// We run CBC's standalone driver (CbcMain0/CbcMain1, the code behind the `cbc` executable) on an
// OsiClpSolverInterface loaded in bulk from the model's CSR matrix, rather than calling
// CbcModel::branchAndBound ourselves: the driver adds CglPreProcess, the default cut generators
// and the primal heuristics (feasibility pump, RINS, diving, ...), which a bare CbcModel lacks and
// which decide whether a time-limited solve finds anything good.
//
// What the Debian 12 build (coinor-libcbc 2.10.8+ds1-1) supports — checked on this machine:
//   * Threads: yes. libCbc is built with CBC_THREAD (it links pthread_create, the driver accepts
//     "-threads N" and logs per-thread statistics). We pass "-threads 100+N" (N > 1 only), CBC's
//     deterministic mode: the tree search is repeatable for a given seed (up to where a time
//     limit cuts it). Both threaded modes leak inside libCbc (reproduced with ASan on the bare
//     driver, no quadlod code involved): "-threads N" loses the node infos of its workers (KBs)
//     whenever the search stops early (time limit, gap); "-threads 100+N" loses a branching
//     object (208 bytes) in some sub-MIPs of its heuristics (CbcHeuristic::smallBranchAndBound).
//     We take the smaller, repeatable one; the test binary suppresses exactly that stack.
//     On 300-item, 40-row knapsacks with a 2 s limit both modes and a single thread reached the
//     same incumbents (4 seeds; 3 of 4 for "-threads 2", which found a better one once).
//   * Wall-clock limit: "-timeMode elapsed" makes "-sec" count wall time (the default counts
//     CPU time, which drifts from the caller's budget both with threads and on a loaded
//     machine). "-sec" does not cover the driver's root LP solve, which on a random 75k-row,
//     87k-column model of the paper's shape took 9 s CPU with dual simplex (primal: 71 s; the
//     Debian Clp barrier crashed) and made a 10 s solve of a 300k-row model last 416 s. So the
//     root LP also gets Clp's own wall-clock limit (a duration counted from the start of that
//     solve), lifted again in the driver callback once it is done.
//   * Pre-processed model size: the driver's callback at whereFrom == 3 ("just before
//     branchAndBound") receives the model whose solver is the CglPreProcess output, so its
//     rows/columns/elements are the pre-solved size. The driver skips pre-processing when the
//     time limit is already used up (then the size is the original one). Without
//     branch-and-bound (pure LPs, root LP cut short, pre-processing proving infeasibility) that
//     callback never comes and we report -1.
//   * MIP start: CbcModel::setMIPStart takes (column name, value) pairs; the driver maps them
//     through pre-processing, fixes the integers, re-solves the LP for the continuous columns
//     and, if that works, installs the result as incumbent before branch-and-bound. We detect
//     acceptance as "an incumbent exists at whereFrom == 3", when no heuristic has run yet.
//     (The driver's "MIPStart provided solution" message is not reliably delivered to a custom
//     message handler: the driver hands the handler to Clp, whose log level then silences it.)
//   * Bogus infeasibility: CglPreProcess can report "infeasible" for feasible models — when the
//     time limit interrupts it (reproduced here with -sec 0.005 on a 300-column knapsack) and in
//     known bugs (coin-or/Cbc issues 466, 737, 740, 747). A claim made by pre-processing, not
//     confirmed by an infeasible root LP, is re-checked by solving again with "-preprocess off"
//     on the remaining time; a feasible initial solution overrides it in any case (solver.cpp).
//   * Re-entrancy: the driver keeps parser state in globals (CbcOrClpParam.cpp:
//     CbcOrClpRead_mode, CbcOrClpEnvironmentIndex, ...), so CBC runs are serialised process-wide.
//   * Output: with noPrinting_ and "-log 0 -slog 0" nothing is printed. With log_level >= 1 CBC
//     prints its own log to stdout (the driver creates message handlers for its internal models
//     that we cannot redirect).
#include "ilp/solver.h"

#include <CbcEventHandler.hpp>
#include <CbcModel.hpp>
#include <CbcSolver.hpp>
#include <CoinError.hpp>
#include <CoinPackedMatrix.hpp>
#include <OsiClpSolverInterface.hpp>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <climits>
#include <cmath>
#include <exception>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

namespace quadlod::ilp {

namespace {

using Clock = std::chrono::steady_clock;

// Shortest round-trip text of a double, for CBC's command line (std::to_string would print
// 1e-7 as "0.000000").
std::string arg(double v) {
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v);
  return ec == std::errc{} ? std::string(buf, end) : std::string("0");
}

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// COIN's "infinity" is a large finite number.
double to_coin(double v) {
  if (v == kInf) return COIN_DBL_MAX;
  if (v == -kInf) return -COIN_DBL_MAX;
  return v;
}
double from_coin(double v) {
  if (v >= 1e50) return kInf;  // CBC reports "no bound / no incumbent" as ~1e50 .. COIN_DBL_MAX
  if (v <= -1e50) return -kInf;
  return v;
}

std::mutex g_cbc_mutex;  // see "Re-entrancy" above

// State shared by the driver callback and the event handlers of one CBC run.
struct RunContext {
  const SolveParams* params = nullptr;
  Clock::time_point t0;

  // Written by the driver callback (the calling thread only).
  bool root_lp_infeasible = false;
  bool root_lp_stopped = false;  // root LP neither optimal nor proven infeasible/unbounded
  bool reached_branch_and_bound = false;
  bool incumbent_before_search = false;
  ModelSize presolved;

  // Progress reporting and the stall clock; the event handlers of CBC's worker threads share it.
  std::mutex progress_mutex;
  double best_reported = kInf;
  double seconds_to_best = 0.0;
  double seconds_to_search = 0.0;
  Clock::time_point last_improvement;  // start of branch-and-bound, then each improvement
  bool stalled = false;
};

// CbcMain1's callback takes no user pointer; the driver calls it on the thread that called
// CbcMain1, so a thread-local pointer reaches the right run.
thread_local RunContext* t_run = nullptr;

int driver_callback(CbcModel* model, int where_from) {
  RunContext* run = t_run;
  if (!run || !model) return 0;
  const OsiSolverInterface* solver = model->solver();
  if (where_from == 1 && solver) {
    // After the root LP of the original model: an infeasible LP is a trustworthy proof.
    run->root_lp_infeasible = solver->isProvenPrimalInfeasible();
    run->root_lp_stopped = !solver->isProvenOptimal() && !solver->isProvenPrimalInfeasible() &&
                           !solver->isProvenDualInfeasible();
    // The wall-clock limit we gave Clp was for this root solve only (see run_cbc); lift it so
    // that the LPs of branch-and-bound are governed by CBC's own limit.
    if (auto* clp = dynamic_cast<OsiClpSolverInterface*>(model->solver()))
      clp->getModelPtr()->setMaximumWallSeconds(-1.0);
  } else if (where_from == 3 && solver) {
    run->reached_branch_and_bound = true;
    run->presolved = {solver->getNumRows(), solver->getNumCols(),
                      static_cast<std::int64_t>(solver->getNumElements()), solver->getNumIntegers()};
    run->incumbent_before_search = model->bestSolution() != nullptr;
    std::lock_guard lock(run->progress_mutex);
    run->last_improvement = Clock::now();
    run->seconds_to_search = seconds_since(run->t0);
  }
  return 0;  // 0 = carry on
}

// Reports incumbent improvements. CBC clones the handler into every model it creates (the
// pre-processed one, one per worker thread), all pointing at the same RunContext.
class ProgressHandler : public CbcEventHandler {
 public:
  explicit ProgressHandler(RunContext* run) : run_(run) {}
  ProgressHandler(const ProgressHandler&) = default;
  ProgressHandler& operator=(const ProgressHandler&) = default;
  CbcEventHandler* clone() const override { return new ProgressHandler(*this); }

  CbcAction event(CbcEvent which) override {
    if (!run_ || !model_) return noAction;
    // "heuristicSolution" fires before the new incumbent is stored, so we poll the stored
    // incumbent on every event that can follow an improvement and report when it changed.
    if (which != solution && which != heuristicSolution && which != node && which != treeStatus &&
        which != endSearch)
      return noAction;
    const double obj = from_coin(model_->getObjValue());
    std::lock_guard lock(run_->progress_mutex);
    if (std::isfinite(obj) && obj < run_->best_reported - 1e-9 * std::max(1.0, std::abs(obj))) {
      run_->best_reported = obj;
      run_->seconds_to_best = seconds_since(run_->t0);
      run_->last_improvement = Clock::now();
      if (run_->params->on_progress) {
        Progress p{obj, from_coin(model_->getBestPossibleObjValue()), run_->seconds_to_best};
        try {
          run_->params->on_progress(p);
        } catch (...) {
          // The contract says the callback must not throw; an exception must not unwind through
          // CBC's C-style stack frames either.
        }
      }
      return noAction;
    }
    // SolveParams::stall_seconds, checked between nodes (a "stop" there ends branch-and-bound).
    if (which == node && std::isfinite(run_->params->stall_seconds) && run_->reached_branch_and_bound &&
        seconds_since(run_->last_improvement) >= run_->params->stall_seconds) {
      run_->stalled = true;
      return stop;
    }
    return noAction;
  }

 private:
  RunContext* run_ = nullptr;
};

// The model in COIN form, built once per solve and loaded into a fresh solver for each run.
struct CoinProblem {
  CoinPackedMatrix matrix;
  std::vector<double> col_lower, col_upper, objective, row_lower, row_upper;
  std::vector<int> integers;
};

CoinProblem to_coin(const Model& model) {
  CoinProblem p;
  const Col n = model.num_cols();
  const Row m = model.num_rows();
  // Row-major CSR straight from the model: one bulk load, no per-row calls.
  std::vector<CoinBigIndex> starts(model.row_starts().begin(), model.row_starts().end());
  std::vector<int> cols(model.matrix_cols().begin(), model.matrix_cols().end());
  const auto coefs = model.matrix_coefs();
  p.matrix = CoinPackedMatrix(false /*row-ordered*/, static_cast<int>(n), static_cast<int>(m),
                              static_cast<CoinBigIndex>(coefs.size()), coefs.data(), cols.data(),
                              starts.data(), nullptr);
  p.col_lower.resize(n);
  p.col_upper.resize(n);
  p.objective.assign(model.objectives().begin(), model.objectives().end());
  for (Col c = 0; c < n; ++c) {
    p.col_lower[c] = to_coin(model.col_lower(c));
    p.col_upper[c] = to_coin(model.col_upper(c));
    if (model.is_integer(c)) p.integers.push_back(static_cast<int>(c));
  }
  p.row_lower.resize(m);
  p.row_upper.resize(m);
  for (Row r = 0; r < m; ++r) {
    p.row_lower[r] = to_coin(model.row_lower(r));
    p.row_upper[r] = to_coin(model.row_upper(r));
  }
  return p;
}

struct RunOutcome {
  SolveStatus status = SolveStatus::Error;
  std::vector<double> solution;
  double best_bound = -kInf;
  std::int64_t nodes = 0, iterations = 0;
  bool reached_branch_and_bound = false;
  bool root_lp_infeasible = false;
  bool root_lp_stopped = false;
  bool incumbent_before_search = false;
  bool time_limit_reached = false;
  bool stalled = false;
  double seconds_to_best = 0.0, seconds_to_search = 0.0;
  ModelSize presolved;
  std::string error;  // CBC threw
};

RunOutcome run_cbc(const Model& model, const CoinProblem& problem, const SolveParams& params,
                   double time_limit, bool preprocess, bool use_start, double cutoff, RunContext& run) {
  RunOutcome out;
  const Col n = model.num_cols();

  OsiClpSolverInterface lp;
  lp.messageHandler()->setLogLevel(0);
  lp.loadProblem(problem.matrix, problem.col_lower.data(), problem.col_upper.data(),
                 problem.objective.data(), problem.row_lower.data(), problem.row_upper.data());
  if (!problem.integers.empty())
    lp.setInteger(problem.integers.data(), static_cast<int>(problem.integers.size()));
  // Osi subtracts its offset: objective = c·x - OsiObjOffset.
  lp.setDblParam(OsiObjOffset, -model.objective_offset());
  // CBC's "-sec" only governs branch-and-bound; the driver's root LP solve ignores it and can
  // take longer than the whole budget on big models. Clp's own wall-clock limit bounds it.
  if (std::isfinite(time_limit)) lp.getModelPtr()->setMaximumWallSeconds(time_limit);

  CbcModel cbc(lp);
  CbcSolverUsefulData data;
  data.noPrinting_ = params.log_level == 0;
  data.useSignalHandler_ = false;  // never touch the host's SIGINT handling
  CbcMain0(cbc, data);

  ProgressHandler progress(&run);
  cbc.passInEventHandler(&progress);  // CBC keeps a clone

  if (use_start) {
    // Names are CBC's defaults ("C0000000", ...): unique by construction, unlike user names.
    const std::vector<double>& start = model.initial_solution();
    std::vector<std::pair<std::string, double>> named(n);
    for (Col c = 0; c < n; ++c) named[c] = {cbc.solver()->getColName(static_cast<int>(c)), start[c]};
    cbc.setMIPStart(named);
  }

  const std::string log = std::to_string(params.log_level);
  const std::string slog = std::to_string(std::max(0, params.log_level - 1));
  // 100 + N: N threads in CBC's deterministic mode (see the header comment).
  const std::string threads = std::to_string(100 + backend::resolve_threads(params));
  const std::string seconds = arg(time_limit);
  const std::string gap = arg(params.relative_gap);
  // CBC reads seed 0 as "seed from the clock"; keep runs repeatable.
  const std::string seed = std::to_string(std::max<std::uint32_t>(1, params.seed % INT_MAX));
  const std::string cutoff_arg = arg(cutoff);
  std::vector<const char*> argv = {"quadlod", "-log", log.c_str(), "-slog", slog.c_str(),
                                   "-timeMode", "elapsed", "-ratioGap", gap.c_str(),
                                   "-randomCbcSeed", seed.c_str()};
  if (std::isfinite(time_limit)) argv.insert(argv.end(), {"-sec", seconds.c_str()});
  if (backend::resolve_threads(params) > 1) argv.insert(argv.end(), {"-threads", threads.c_str()});
  if (!preprocess || params.light) argv.insert(argv.end(), {"-preprocess", "off"});
  if (params.light) argv.insert(argv.end(), {"-cutsOnOff", "off", "-heuristicsOnOff", "off"});
  if (std::isfinite(cutoff)) argv.insert(argv.end(), {"-cutoff", cutoff_arg.c_str()});
  argv.insert(argv.end(), {"-solve", "-quit"});

  run.root_lp_infeasible = run.root_lp_stopped = run.reached_branch_and_bound = false;
  run.incumbent_before_search = false;
  run.stalled = false;
  run.seconds_to_search = 0.0;
  run.presolved = {};
  t_run = &run;
  try {
    CbcMain1(static_cast<int>(argv.size()), argv.data(), cbc, driver_callback, data);
  } catch (const CoinError& e) {
    out.error = "CBC threw " + e.className() + "::" + e.methodName() + ": " + e.message();
  } catch (const std::exception& e) {
    out.error = std::string("CBC threw: ") + e.what();
  } catch (...) {
    out.error = "CBC threw an unknown exception";
  }
  t_run = nullptr;

  out.reached_branch_and_bound = run.reached_branch_and_bound;
  out.root_lp_infeasible = run.root_lp_infeasible;
  out.root_lp_stopped = run.root_lp_stopped;
  out.incumbent_before_search = run.incumbent_before_search;
  out.stalled = run.stalled;
  out.seconds_to_best = run.seconds_to_best;
  out.seconds_to_search = run.seconds_to_search;
  out.presolved = run.presolved;
  if (!out.error.empty()) return out;

  out.time_limit_reached = cbc.isSecondsLimitReached() || run.root_lp_stopped;
  out.nodes = cbc.getNodeCount();
  out.iterations = cbc.getIterationCount();
  // An interrupted dual simplex leaves an objective value that is not a proven bound.
  out.best_bound = run.root_lp_stopped ? -kInf : from_coin(cbc.getBestPossibleObjValue());
  const double* best = cbc.bestSolution();
  if (best) out.solution.assign(best, best + n);

  const OsiSolverInterface* solver = cbc.solver();
  if (problem.integers.empty() && cbc.status() == -1 && solver) {
    // Pure LP: the driver solved it with Clp and never started branch-and-bound.
    if (solver->isProvenOptimal()) {
      out.status = SolveStatus::Optimal;
      if (out.solution.empty()) out.solution.assign(solver->getColSolution(), solver->getColSolution() + n);
      out.best_bound = solver->getObjValue();
    } else if (solver->isProvenPrimalInfeasible()) {
      out.status = SolveStatus::Infeasible;
    } else if (solver->isProvenDualInfeasible()) {
      out.status = SolveStatus::Unbounded;
    } else {
      out.status = out.solution.empty() ? SolveStatus::NoSolution : SolveStatus::Feasible;
    }
  } else if (cbc.isProvenOptimal() && !out.solution.empty()) {
    out.status = SolveStatus::Optimal;
  } else if (cbc.isProvenInfeasible()) {
    out.status = SolveStatus::Infeasible;
  } else if (cbc.isContinuousUnbounded()) {
    out.status = SolveStatus::Unbounded;
  } else if (!out.solution.empty()) {
    out.status = SolveStatus::Feasible;
  } else if (cbc.isAbandoned()) {
    out.status = SolveStatus::Error;
    out.error = "CBC abandoned the search (numerical difficulties)";
  } else {
    out.status = SolveStatus::NoSolution;  // time (or node) limit before any incumbent
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Process isolation (SolveParams::isolate_process). The child runs run_cbc and streams records
// through a pipe: 'P' + 3 doubles for each progress event, 'R' + length + the RunOutcome.

void write_all(int fd, const char* data, std::size_t n) {
  while (n > 0) {
    const ssize_t k = ::write(fd, data, n);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return;  // the parent is gone: nothing left to tell
    data += k;
    n -= static_cast<std::size_t>(k);
  }
}

struct Packer {
  std::string bytes;
  template <class T>
  void put(const T& v) { bytes.append(reinterpret_cast<const char*>(&v), sizeof v); }
  void put_doubles(const std::vector<double>& v) {
    put<std::uint64_t>(v.size());
    if (!v.empty()) bytes.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double));
  }
  void put_string(const std::string& s) {
    put<std::uint64_t>(s.size());
    bytes.append(s);
  }
};

struct Unpacker {
  const char* p;
  const char* end;
  bool ok = true;
  template <class T>
  T get() {
    T v{};
    if (end - p < static_cast<std::ptrdiff_t>(sizeof v)) { ok = false; return v; }
    std::memcpy(&v, p, sizeof v);
    p += sizeof v;
    return v;
  }
  std::vector<double> get_doubles() {
    const auto n = get<std::uint64_t>();
    if (!ok || static_cast<std::uint64_t>(end - p) / sizeof(double) < n) { ok = false; return {}; }
    std::vector<double> v(n);
    if (n > 0) std::memcpy(v.data(), p, n * sizeof(double));  // data() of an empty vector may be null
    p += n * sizeof(double);
    return v;
  }
  std::string get_string() {
    const auto n = get<std::uint64_t>();
    if (!ok || static_cast<std::uint64_t>(end - p) < n) { ok = false; return {}; }
    std::string s(n > 0 ? std::string(p, n) : std::string());
    p += n;
    return s;
  }
};

std::string pack(const RunOutcome& o) {
  Packer w;
  w.put<int>(static_cast<int>(o.status));
  w.put_doubles(o.solution);
  w.put(o.best_bound);
  w.put(o.nodes);
  w.put(o.iterations);
  for (bool b : {o.reached_branch_and_bound, o.root_lp_infeasible, o.root_lp_stopped,
                 o.incumbent_before_search, o.time_limit_reached, o.stalled})
    w.put<std::uint8_t>(b);
  w.put(o.seconds_to_best);
  w.put(o.seconds_to_search);
  for (std::int64_t v : {o.presolved.rows, o.presolved.cols, o.presolved.nonzeros, o.presolved.integer_cols})
    w.put(v);
  w.put_string(o.error);
  return w.bytes;
}

bool unpack(const char* data, std::size_t n, RunOutcome& o) {
  Unpacker r{data, data + n};
  o.status = static_cast<SolveStatus>(r.get<int>());
  o.solution = r.get_doubles();
  o.best_bound = r.get<double>();
  o.nodes = r.get<std::int64_t>();
  o.iterations = r.get<std::int64_t>();
  o.reached_branch_and_bound = r.get<std::uint8_t>();
  o.root_lp_infeasible = r.get<std::uint8_t>();
  o.root_lp_stopped = r.get<std::uint8_t>();
  o.incumbent_before_search = r.get<std::uint8_t>();
  o.time_limit_reached = r.get<std::uint8_t>();
  o.stalled = r.get<std::uint8_t>();
  o.seconds_to_best = r.get<double>();
  o.seconds_to_search = r.get<double>();
  o.presolved.rows = r.get<std::int64_t>();
  o.presolved.cols = r.get<std::int64_t>();
  o.presolved.nonzeros = r.get<std::int64_t>();
  o.presolved.integer_cols = r.get<std::int64_t>();
  o.error = r.get_string();
  return r.ok && r.p == r.end;
}

// run_cbc in a child process. `incident` says what went wrong with the child, if anything.
RunOutcome run_cbc_isolated(const Model& model, const CoinProblem& problem, const SolveParams& params,
                            double time_limit, bool preprocess, bool use_start, double cutoff,
                            RunContext& run, std::string& incident) {
  int fds[2];
  if (::pipe(fds) != 0) return run_cbc(model, problem, params, time_limit, preprocess, use_start, cutoff, run);
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return run_cbc(model, problem, params, time_limit, preprocess, use_start, cutoff, run);
  }
  if (pid == 0) {
    ::close(fds[0]);
    const int out = fds[1];
    SolveParams child = params;
    if (params.on_progress)
      child.on_progress = [out](const Progress& p) {
        Packer w;
        w.put('P');
        w.put(p.objective);
        w.put(p.best_bound);
        w.put(p.seconds);
        write_all(out, w.bytes.data(), w.bytes.size());
      };
    run.params = &child;
    const std::string result = pack(run_cbc(model, problem, child, time_limit, preprocess, use_start, cutoff, run));
    Packer w;
    w.put('R');
    w.put<std::uint64_t>(result.size());
    write_all(out, w.bytes.data(), w.bytes.size());
    write_all(out, result.data(), result.size());
    ::close(out);
    ::_exit(0);  // no destructors, no atexit handlers of the parent's state
  }
  ::close(fds[1]);
  const Clock::time_point start = Clock::now();
  const double allowed = std::isfinite(time_limit) ? time_limit + std::max(2.0, 0.25 * time_limit) : kInf;
  std::string buffer;
  RunOutcome out;
  bool have_result = false, killed = false;
  char chunk[1 << 16];
  for (;;) {
    int wait_ms = -1;
    if (std::isfinite(allowed)) {
      const double left = allowed - seconds_since(start);
      if (left <= 0) {
        ::kill(pid, SIGKILL);
        killed = true;
        break;
      }
      wait_ms = static_cast<int>(std::ceil(left * 1000.0));
    }
    pollfd pfd{fds[0], POLLIN, 0};
    const int ready = ::poll(&pfd, 1, wait_ms);
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) continue;  // re-check the deadline
    const ssize_t k = ::read(fds[0], chunk, sizeof chunk);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) break;  // EOF: the child is done (or died)
    buffer.append(chunk, static_cast<std::size_t>(k));
    // Consume complete records.
    std::size_t pos = 0;
    for (;;) {
      if (buffer.size() - pos < 1) break;
      const char tag = buffer[pos];
      if (tag == 'P') {
        constexpr std::size_t size = 1 + 3 * sizeof(double);
        if (buffer.size() - pos < size) break;
        Progress p{};
        std::memcpy(&p.objective, buffer.data() + pos + 1, sizeof(double));
        std::memcpy(&p.best_bound, buffer.data() + pos + 1 + sizeof(double), sizeof(double));
        std::memcpy(&p.seconds, buffer.data() + pos + 1 + 2 * sizeof(double), sizeof(double));
        pos += size;
        if (params.on_progress) {
          try {
            params.on_progress(p);
          } catch (...) {
          }
        }
      } else if (tag == 'R') {
        if (buffer.size() - pos < 1 + sizeof(std::uint64_t)) break;
        std::uint64_t n = 0;
        std::memcpy(&n, buffer.data() + pos + 1, sizeof n);
        if (buffer.size() - pos < 1 + sizeof n + n) break;
        have_result = unpack(buffer.data() + pos + 1 + sizeof n, n, out);
        pos += 1 + sizeof n + n;
      } else {
        pos = buffer.size();  // garbage: drop it (cannot happen with our own child)
      }
    }
    buffer.erase(0, pos);
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (have_result) return out;
  out = RunOutcome{};
  out.status = SolveStatus::NoSolution;
  if (killed) {
    incident = "CBC overran its time limit (" + arg(time_limit) + " s) and was stopped";
    out.time_limit_reached = true;
  } else if (WIFSIGNALED(status)) {
    incident = std::string("CBC crashed (") + strsignal(WTERMSIG(status)) +
               ") inside the solver library; the solve ran in a child process, so only it was lost";
  } else {
    incident = "the CBC child process ended without a result (exit status " +
               std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")";
  }
  return out;
}

class CbcBackend final : public Solver {
 public:
  std::string name() const override { return "cbc"; }
  SolveResult solve(const Model& model, const SolveParams& params) override;
};

SolveResult CbcBackend::solve(const Model& model, const SolveParams& params) {
  const Clock::time_point t0 = Clock::now();
  SolveResult result;
  result.backend = name();
  result.call = CallStatus::Ok;
  result.status = SolveStatus::Error;

  const bool has_start = model.has_initial_solution();
  const bool start_fits = has_start && model.initial_solution().size() == model.num_cols();
  result.start = !has_start ? StartStatus::NotGiven : start_fits ? StartStatus::Unknown : StartStatus::WrongSize;
  if (result.start == StartStatus::WrongSize)
    backend::note(result, CallStatus::Warning,
                  "initial solution has " + std::to_string(model.initial_solution().size()) +
                      " values for " + std::to_string(model.num_cols()) + " columns; ignored");

  const auto fail = [&](const std::string& why) {
    backend::note(result, CallStatus::Error, why);
    result.status = SolveStatus::Error;
    backend::finish(model, params, result);
    result.seconds = seconds_since(t0);
    return result;
  };
  if (std::string bad = backend::check_params(params); !bad.empty()) return fail("invalid parameters: " + bad);
  if (model.num_cols() == 0) return fail("model has no columns");

  CoinProblem problem;
  try {
    problem = to_coin(model);
  } catch (const std::exception& e) {
    return fail(std::string("building the CBC model failed: ") + e.what());
  }

  std::lock_guard serialise(g_cbc_mutex);
  RunContext run;
  run.params = &params;
  run.t0 = t0;

  const bool use_start = start_fits && params.start_as_mip_start;
  if (start_fits && !use_start) result.start = StartStatus::NotUsed;
  // A start that is not handed over as MIP start still bounds the search: CBC only looks for
  // solutions better than it ("-cutoff"), and a search that ends without one proves the start
  // optimal (the floor in backend::finish returns it).
  double cutoff = kInf;
  if (start_fits && !use_start && model.is_feasible(model.initial_solution(), params.feasibility_tolerance)) {
    const double start_obj = model.evaluate(model.initial_solution());
    cutoff = start_obj + 1e-7 * std::max(1.0, std::abs(start_obj));
  }
  // The budget counts from entry into solve(): converting and loading a big model takes a
  // noticeable part of it (about 1 s for 1.45M nonzeros).
  const double budget = std::max(1e-3, params.time_limit_seconds - seconds_since(t0));
  std::string incident;
  auto run_once = [&](double seconds, bool preprocess) {
    return params.isolate_process
               ? run_cbc_isolated(model, problem, params, seconds, preprocess, use_start, cutoff, run, incident)
               : run_cbc(model, problem, params, seconds, preprocess, use_start, cutoff, run);
  };
  RunOutcome out = run_once(budget, /*preprocess=*/true);
  if (std::isfinite(cutoff) && out.status == SolveStatus::Infeasible && out.error.empty()) {
    // Nothing better than the start exists (search complete) or was found (time ran out).
    // Only a finished search or an infeasible root LP proves it; pre-processing cut short by the
    // time limit also says "infeasible" (see the header comment).
    const bool proven =
        (out.reached_branch_and_bound && !out.time_limit_reached && !out.stalled) || out.root_lp_infeasible;
    out.status = proven ? SolveStatus::Optimal : SolveStatus::NoSolution;
    if (out.status == SolveStatus::Optimal) out.best_bound = cutoff;
  }
  result.presolved = out.presolved;
  if (use_start && out.reached_branch_and_bound)
    result.start = out.incumbent_before_search ? StartStatus::Accepted : StartStatus::Rejected;

  if (out.status == SolveStatus::Infeasible && !out.reached_branch_and_bound &&
      !out.root_lp_infeasible && out.error.empty()) {
    // The claim comes from CglPreProcess alone (see the header comment): check it.
    const double remaining = params.time_limit_seconds - seconds_since(t0);
    if (remaining < 0.01) {
      backend::note(result, CallStatus::Warning,
                    "CBC pre-processing claimed infeasibility as the time limit ran out; not trusted");
      out.status = SolveStatus::NoSolution;
    } else {
      const std::int64_t nodes = out.nodes, iterations = out.iterations;
      out = run_once(remaining, /*preprocess=*/false);
      out.nodes += nodes;
      out.iterations += iterations;
      backend::note(result, CallStatus::Warning,
                    "CBC pre-processing claimed infeasibility; re-solved without pre-processing: " +
                        std::string(to_string(out.status)));
      if (use_start && out.reached_branch_and_bound)
        result.start = out.incumbent_before_search ? StartStatus::Accepted : StartStatus::Rejected;
    }
  }

  if (out.root_lp_stopped) {
    const bool out_of_time = seconds_since(t0) >= 0.95 * params.time_limit_seconds;
    backend::note(result, out_of_time ? CallStatus::Warning : CallStatus::Error,
                  std::string(out_of_time ? "the time limit ran out while" : "Clp gave up") +
                      " solving the root LP relaxation (" + std::to_string(model.num_rows()) +
                      " rows); CBC found no solution");
  }
  if (!out.error.empty()) backend::note(result, CallStatus::Error, out.error);
  if (!incident.empty()) backend::note(result, CallStatus::Warning, incident);
  result.status = out.status;
  result.solution = std::move(out.solution);
  result.best_bound = out.best_bound;
  result.nodes = out.nodes;
  result.iterations = out.iterations;
  result.stalled = out.stalled;
  result.seconds_to_best = out.seconds_to_best;
  result.seconds_to_search = out.seconds_to_search;
  if (out.stalled && result.status == SolveStatus::Optimal) result.status = SolveStatus::Feasible;
  backend::finish(model, params, result);
  result.seconds = seconds_since(t0);
  return result;
}

}  // namespace

std::unique_ptr<Solver> make_cbc_solver() { return std::make_unique<CbcBackend>(); }

}  // namespace quadlod::ilp
