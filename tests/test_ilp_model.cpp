// Tests of the solver-neutral ILP model (src/ilp/model.h) and the CBC backend (src/ilp/solver.h).
//
// Small models with hand-computed optima, an exhaustive-enumeration oracle on random binary
// programs, and the MIP-start guarantee ("a solve is never worse than its start"). No timing
// assertions: time limits are only used to force the time-limited code paths.
#include "ilp/model.h"
#include "ilp/solver.h"

#include <gtest/gtest.h>

#include <CoinLpIO.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

// LeakSanitizer suppression for the sanitizer build of this test binary (a no-op elsewhere).
// Reason: CBC 2.10.8 (Debian 12) leaks 2 x 104 bytes (a CbcDynamicPseudoCostBranchingObject and
// its holder) in the sub-MIPs its heuristics run through CbcHeuristic::smallBranchAndBound when
// its tree search is threaded ("-threads 100+N", which the backend passes for threads > 1).
// Reproduced with CBC's own driver and no quadlod code (a 60-item, 6-row knapsack, -threads 102);
// not reproducible single-threaded. Only stacks through that CBC function are suppressed; the
// leaks it holds indirectly are suppressed with it.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:CbcHeuristic::smallBranchAndBound\n";
}

namespace {

using namespace quadlod::ilp;

// "item12". Appending instead of `"item" + std::to_string(12)`, which trips GCC 12's
// -Wrestrict false positive (GCC bug 105651).
std::string numbered(std::string prefix, double i) {
  std::ostringstream s;
  s << i;
  prefix += s.str();
  return prefix;
}

// Tests that expect a proven optimum must not depend on machine speed (the sanitizer build on
// a loaded machine is 50x slower), so they get a generous limit instead of the 5 s default.
SolveParams generous() {
  SolveParams p;
  p.time_limit_seconds = 300.0;
  return p;
}

SolveResult solve(const Model& model, const SolveParams& params = generous()) {
  auto solver = make_solver("cbc");
  EXPECT_NE(solver, nullptr);
  return solver->solve(model, params);
}

std::string describe(const SolveResult& r) {
  std::ostringstream s;
  s << "call=" << to_string(r.call) << " status=" << to_string(r.status) << " obj=" << r.objective
    << " bound=" << r.best_bound << " start=" << to_string(r.start) << " message='" << r.message << "'";
  return s.str();
}

// Checks the invariants every solved result must satisfy, plus the expected optimum.
void expect_optimal(const Model& model, const SolveResult& r, double optimum) {
  ASSERT_EQ(r.status, SolveStatus::Optimal) << describe(r);
  ASSERT_EQ(r.solution.size(), model.num_cols());
  EXPECT_TRUE(model.is_feasible(r.solution, 1e-6)) << model.describe_violation(r.solution);
  EXPECT_NEAR(r.objective, optimum, 1e-6) << describe(r);
  EXPECT_NEAR(model.evaluate(r.solution), r.objective, 1e-9);
  EXPECT_LE(r.best_bound, r.objective + 1e-9);
  EXPECT_LE(r.gap, 1e-4 + 1e-12);
  for (Col c = 0; c < model.num_cols(); ++c) {
    if (model.is_integer(c)) {
      EXPECT_EQ(r.solution[c], std::round(r.solution[c])) << "column " << c;
    }
  }
  EXPECT_EQ(r.built.rows, static_cast<std::int64_t>(model.num_rows()));
  EXPECT_EQ(r.built.cols, static_cast<std::int64_t>(model.num_cols()));
  EXPECT_EQ(r.built.nonzeros, static_cast<std::int64_t>(model.num_nonzeros()));
  EXPECT_EQ(r.backend, "cbc");
}

// Exhaustive minimum over all 0/1 assignments of an all-binary model; nullopt if infeasible.
std::optional<double> enumerate_binary(const Model& model) {
  const Col n = model.num_cols();
  std::optional<double> best;
  std::vector<double> x(n);
  for (std::uint32_t bits = 0; bits < (1u << n); ++bits) {
    for (Col c = 0; c < n; ++c) x[c] = (bits >> c) & 1u;
    if (!model.is_feasible(x, 1e-9)) continue;
    const double obj = model.evaluate(x);
    if (!best || obj < *best) best = obj;
  }
  return best;
}

// A multi-row 0/1 knapsack (maximise value, written as minimising -value): many rows sharing all
// items make it hard enough that CBC does not finish within a few hundredths of a second.
Model random_knapsack(int items, int rows, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> d(1, 100);
  Model m;
  m.reserve(items, rows, static_cast<std::size_t>(items) * rows);
  for (int j = 0; j < items; ++j) m.add_binary(-d(rng), numbered("item", j));
  std::vector<Term> terms(items);
  for (int i = 0; i < rows; ++i) {
    double total = 0;
    for (int j = 0; j < items; ++j) {
      terms[j] = {static_cast<Col>(j), static_cast<double>(d(rng))};
      total += terms[j].coef;
    }
    m.add_le(terms, std::floor(total / 3), numbered("capacity", i));
  }
  return m;
}

// Greedy feasible point of a knapsack built by random_knapsack: add items by value while every
// row still fits.
std::vector<double> greedy_start(const Model& m) {
  std::vector<double> x(m.num_cols(), 0.0);
  std::vector<Col> order(m.num_cols());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](Col a, Col b) { return m.objective(a) < m.objective(b); });
  for (Col c : order) {
    x[c] = 1.0;
    if (!m.is_feasible(x, 0.0)) x[c] = 0.0;
  }
  return x;
}

// A 300-item, 40-row knapsack carrying its greedy point as initial solution, handed to CBC as a
// cutoff only: a search CBC cannot finish quickly, with a floor for its result.
Model knapsack_with_floor(unsigned seed) {
  Model m = random_knapsack(300, 40, seed);
  m.set_initial_solution(greedy_start(m));
  return m;
}

// The floor guarantee (solver.h): a feasible solution at least as good as the start.
void expect_start_is_the_floor(const Model& m, const SolveResult& r) {
  ASSERT_TRUE(r.has_solution()) << describe(r);
  EXPECT_TRUE(m.is_feasible(r.solution)) << m.describe_violation(r.solution);
  EXPECT_LE(r.objective, m.evaluate(m.initial_solution()) + 1e-9) << describe(r);
}

// ---------------------------------------------------------------------------------------------
// Model

TEST(IlpModel, RowsAreSortedMergedAndStoredAsCsr) {
  Model m;
  const Col x = m.add_binary(1.0, "x");
  const Col y = m.add_integer(-3, 7, 2.0);  // unnamed
  const Col z = m.add_continuous(-kInf, kInf, 0.0, "z");
  const Row r0 = m.add_le({{z, 1.0}, {x, 2.0}, {z, 3.0}, {y, 0.0}}, 5.0, "first");
  const Row r1 = m.add_range(-1.0, {{y, 1.0}, {y, -1.0}}, 1.0);  // cancels to an empty row
  const Row r2 = m.add_ge({{y, 4.0}}, -2.0, "third");
  EXPECT_EQ(m.num_cols(), 3u);
  EXPECT_EQ(m.num_rows(), 3u);
  EXPECT_EQ(m.num_nonzeros(), 3u);
  EXPECT_EQ(m.num_integer_cols(), 2u);
  ASSERT_EQ(m.row_cols(r0).size(), 2u);
  EXPECT_EQ(m.row_cols(r0)[0], x);
  EXPECT_EQ(m.row_cols(r0)[1], z);
  EXPECT_EQ(m.row_coefs(r0)[0], 2.0);
  EXPECT_EQ(m.row_coefs(r0)[1], 4.0);
  EXPECT_TRUE(m.row_cols(r1).empty());
  EXPECT_EQ(m.row_cols(r2).size(), 1u);
  EXPECT_EQ(m.row_lower(r0), -kInf);
  EXPECT_EQ(m.row_upper(r2), kInf);
  EXPECT_EQ(m.col_name(x), "x");
  EXPECT_EQ(m.col_name(y), "");
  EXPECT_EQ(m.col_name(z), "z");
  EXPECT_EQ(m.row_name(r0), "first");
  EXPECT_EQ(m.row_name(r1), "");
  EXPECT_EQ(m.row_name(r2), "third");
  const std::vector<std::uint32_t> starts(m.row_starts().begin(), m.row_starts().end());
  EXPECT_EQ(starts, (std::vector<std::uint32_t>{0, 2, 2, 3}));
}

TEST(IlpModel, NamesAreOptionalAndCostNothingWhenUnused) {
  Model m;
  for (int i = 0; i < 1000; ++i) m.add_binary();
  for (int i = 0; i < 1000; ++i) m.add_le({{static_cast<Col>(i), 1.0}}, 1.0);
  EXPECT_EQ(m.col_name(999), "");
  EXPECT_EQ(m.row_name(999), "");
  // A late first name still leaves the earlier entries unnamed.
  const Col named = m.add_binary(0.0, "late");
  EXPECT_EQ(m.col_name(named), "late");
  EXPECT_EQ(m.col_name(0), "");
}

TEST(IlpModel, ContractViolationsThrow) {
  Model m;
  const Col x = m.add_binary();
  EXPECT_THROW(m.add_var(VarType::Binary, 0.0, 2.0), std::invalid_argument);
  EXPECT_THROW(m.add_var(VarType::Integer, 3.0, 2.0), std::invalid_argument);
  EXPECT_THROW(m.add_var(VarType::Continuous, std::nan(""), 1.0), std::invalid_argument);
  EXPECT_THROW(m.add_var(VarType::Continuous, kInf, kInf), std::invalid_argument);
  EXPECT_THROW(m.add_var(VarType::Continuous, 0.0, 1.0, kInf), std::invalid_argument);
  EXPECT_THROW(m.add_le({{x + 1, 1.0}}, 1.0), std::invalid_argument);
  EXPECT_THROW(m.add_le({{x, std::nan("")}}, 1.0), std::invalid_argument);
  EXPECT_THROW(m.add_range(2.0, {{x, 1.0}}, 1.0), std::invalid_argument);
  EXPECT_THROW(m.add_eq({{x, 1.0}}, kInf), std::invalid_argument);
  EXPECT_THROW(m.set_bounds(x, -1.0, 1.0), std::invalid_argument);
  EXPECT_THROW(m.set_initial_solution({1.0, 2.0}), std::invalid_argument);
  // Nothing half-added after a rejected call.
  EXPECT_EQ(m.num_cols(), 1u);
  EXPECT_EQ(m.num_rows(), 0u);
  EXPECT_EQ(m.num_nonzeros(), 0u);
}

TEST(IlpModel, EvaluateAndViolationsCoverBoundsIntegralityAndRows) {
  Model m;
  const Col x = m.add_binary(2.0, "x");
  const Col y = m.add_integer(0, 10, -1.0, "y");
  const Col z = m.add_continuous(0.0, 1.5, 0.5, "z");
  m.set_objective_offset(3.0);
  m.add_range(1.0, {{x, 1.0}, {y, 1.0}, {z, 1.0}}, 4.0, "band");
  m.add_eq({{x, 1.0}, {z, -2.0}}, 0.0, "link");

  const std::vector<double> good{1.0, 2.0, 0.5};
  EXPECT_DOUBLE_EQ(m.evaluate(good), 2.0 - 2.0 + 0.25 + 3.0);
  EXPECT_EQ(m.max_violation(good), 0.0);
  EXPECT_TRUE(m.is_feasible(good));
  EXPECT_EQ(m.describe_violation(good), "");

  EXPECT_NEAR(m.max_violation(std::vector<double>{1.0, 2.5, 0.5}), 0.5, 1e-12);  // integrality
  EXPECT_NEAR(m.max_violation(std::vector<double>{1.0, 2.0, 2.0}), 3.0, 1e-12);  // link row: 1-4
  EXPECT_NEAR(m.max_violation(std::vector<double>{0.0, -1.0, 0.0}), 2.0, 1e-12);  // band: -1 < 1
  EXPECT_NE(m.describe_violation(std::vector<double>{1.0, 2.0, 2.0}).find("'link'"), std::string::npos);
  EXPECT_EQ(m.max_violation(std::vector<double>{1.0}), kInf);
  EXPECT_TRUE(std::isnan(m.evaluate(std::vector<double>{1.0})));
  EXPECT_EQ(m.max_violation(std::vector<double>{1.0, std::nan(""), 0.5}), kInf);
}

Model lp_test_model() {
  Model m;
  const Col x = m.add_binary(1.0, "x");
  const Col y = m.add_integer(-5, 5, -2.0, "y[1]");     // '[' is not allowed in LP names
  const Col z = m.add_continuous(-kInf, kInf, 0.25, "e1");  // looks like an exponent
  const Col w = m.add_continuous(0.0, 3.0, 0.0);         // unnamed
  m.set_objective_offset(5.0);
  m.add_ge({{x, 1.0}, {y, 1.0}}, 1.0, "cover_0");
  m.add_range(-2.0, {{y, 2.0}, {z, -1.0}, {w, 1.0}}, 4.0, "band");
  m.add_eq({{z, 1.0}, {w, 1.0}}, 2.0);  // unnamed row
  m.add_le({{x, 1.0}}, 1.0, "cover_0");  // duplicate name
  return m;
}

TEST(IlpModel, WriteLpContainsRowNames) {
  const Model m = lp_test_model();
  const auto path = std::filesystem::temp_directory_path() / "quadlod_test_ilp_model.lp";
  ASSERT_EQ(m.write_lp(path), "");
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string lp = text.str();
  EXPECT_NE(lp.find("Minimize"), std::string::npos);
  EXPECT_NE(lp.find(" cover_0:"), std::string::npos);
  EXPECT_NE(lp.find(" cover_0_1:"), std::string::npos);  // made unique
  EXPECT_NE(lp.find(" band_lo:"), std::string::npos);      // a range becomes two rows
  EXPECT_NE(lp.find(" band_hi:"), std::string::npos);
  EXPECT_NE(lp.find(" r2:"), std::string::npos);  // default row name
  EXPECT_NE(lp.find("y_1_"), std::string::npos);  // sanitised column name
  EXPECT_NE(lp.find("_e1"), std::string::npos);
  EXPECT_NE(lp.find("General"), std::string::npos);
  EXPECT_NE(lp.find("Binary"), std::string::npos);
  EXPECT_NE(lp.find("End"), std::string::npos);
  std::filesystem::remove(path);

  const std::string error = m.write_lp("/nonexistent-dir/quadlod.lp");
  EXPECT_NE(error.find("/nonexistent-dir/quadlod.lp"), std::string::npos) << error;
}

// Oracle for the LP writer: COIN's own LP reader must read back the same model.
TEST(IlpModel, WriteLpReadsBackWithCoinLpIO) {
  const Model m = lp_test_model();
  const auto path = std::filesystem::temp_directory_path() / "quadlod_test_ilp_roundtrip.lp";
  ASSERT_EQ(m.write_lp(path), "");
  CoinLpIO reader;
  reader.messageHandler()->setLogLevel(0);
  reader.readLp(path.c_str());
  std::filesystem::remove(path);
  ASSERT_EQ(reader.getNumCols(), 4);
  ASSERT_EQ(reader.getNumRows(), 5);  // the range row is split in two
  const double* obj = reader.getObjCoefficients();
  const double* lo = reader.getColLower();
  const double* hi = reader.getColUpper();
  for (Col c = 0; c < m.num_cols(); ++c) {
    EXPECT_EQ(obj[c], m.objective(c)) << c;
    EXPECT_EQ(reader.isInteger(static_cast<int>(c)), m.is_integer(c)) << c;
    EXPECT_EQ(lo[c] <= -1e30 ? -kInf : lo[c], m.col_lower(c)) << c;
    EXPECT_EQ(hi[c] >= 1e30 ? kInf : hi[c], m.col_upper(c)) << c;
  }
  EXPECT_EQ(reader.objectiveOffset(), 5.0);  // CoinLpIO: objective = c·x + offset
  const CoinPackedMatrix* rows = reader.getMatrixByRow();
  EXPECT_EQ(rows->getNumElements(), 2 + 3 + 3 + 2 + 1);
  EXPECT_EQ(std::string(reader.rowName(0)), "cover_0");
  EXPECT_EQ(reader.getRowLower()[1], -2.0);
  EXPECT_EQ(reader.getRowUpper()[2], 4.0);
}

// ---------------------------------------------------------------------------------------------
// CBC: known optima

TEST(IlpCbc, Knapsack) {
  // values 10 13 7 8 4, weights 5 7 4 3 1, capacity 10: best is items {0, 3, 4} (w 9, v 22).
  const std::array<double, 5> value{10, 13, 7, 8, 4}, weight{5, 7, 4, 3, 1};
  Model m;
  std::vector<Term> row;
  for (std::size_t i = 0; i < value.size(); ++i) row.push_back({m.add_binary(-value[i]), weight[i]});
  m.add_le(row, 10.0, "capacity");
  const SolveResult r = solve(m);
  expect_optimal(m, r, -22.0);
  EXPECT_EQ(r.solution, (std::vector<double>{1, 0, 0, 1, 1}));
  EXPECT_EQ(r.call, CallStatus::Ok) << r.message;
  EXPECT_EQ(r.start, StartStatus::NotGiven);
  ASSERT_EQ(enumerate_binary(m), -22.0);
}

TEST(IlpCbc, SetCover) {
  // Elements 1..6; the cheapest cover is S0 + S5 (cost 6); nothing of cost 5 covers all.
  const std::vector<std::vector<int>> sets{{1, 2, 3}, {2, 4}, {3, 4, 5}, {5, 6}, {1, 6}, {4, 5, 6}};
  const std::vector<double> cost{3, 2, 3, 2, 2, 3};
  Model m;
  for (std::size_t s = 0; s < sets.size(); ++s) m.add_binary(cost[s], numbered("S", s));
  for (int e = 1; e <= 6; ++e) {
    std::vector<Term> row;
    for (std::size_t s = 0; s < sets.size(); ++s)
      if (std::count(sets[s].begin(), sets[s].end(), e)) row.push_back({static_cast<Col>(s), 1.0});
    m.add_ge(row, 1.0, numbered("cover_", e));
  }
  const SolveResult r = solve(m);
  expect_optimal(m, r, 6.0);
  EXPECT_EQ(r.solution, (std::vector<double>{1, 0, 0, 0, 0, 1}));
  ASSERT_EQ(enumerate_binary(m), 6.0);
}

TEST(IlpCbc, Assignment) {
  // Classic 4x4 instance: 0->1 (2), 1->0 (6), 2->2 (1), 3->3 (4) = 13.
  const double cost[4][4] = {{9, 2, 7, 8}, {6, 4, 3, 7}, {5, 8, 1, 8}, {7, 6, 9, 4}};
  Model m;
  Col x[4][4];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) x[i][j] = m.add_binary(cost[i][j]);
  for (int i = 0; i < 4; ++i)
    m.add_eq({{x[i][0], 1}, {x[i][1], 1}, {x[i][2], 1}, {x[i][3], 1}}, 1.0, numbered("worker", i));
  for (int j = 0; j < 4; ++j)
    m.add_eq({{x[0][j], 1}, {x[1][j], 1}, {x[2][j], 1}, {x[3][j], 1}}, 1.0, numbered("job", j));
  // Oracle: all 24 permutations.
  std::array<int, 4> perm{0, 1, 2, 3};
  double best = kInf;
  do {
    best = std::min(best, cost[0][perm[0]] + cost[1][perm[1]] + cost[2][perm[2]] + cost[3][perm[3]]);
  } while (std::next_permutation(perm.begin(), perm.end()));
  ASSERT_EQ(best, 13.0);
  const SolveResult r = solve(m);
  expect_optimal(m, r, 13.0);
  EXPECT_EQ(r.solution[x[0][1]], 1.0);
  EXPECT_EQ(r.solution[x[1][0]], 1.0);
  EXPECT_EQ(r.solution[x[2][2]], 1.0);
  EXPECT_EQ(r.solution[x[3][3]], 1.0);
}

TEST(IlpCbc, GeneralIntegerAndContinuousWithOffset) {
  // max x + y  s.t. 2x + 3y <= 12.5, x - y >= 0.5, x integer in [0, 10], y >= 0 continuous.
  // For integer x the best y is min((12.5 - 2x)/3, x - 0.5); x = 6 gives y = 1/6, value 37/6
  // (x = 7 makes y negative). With objective offset 10 the minimum of 10 - (x + y) is 23/6.
  Model m;
  const Col x = m.add_integer(0, 10, -1.0, "x");
  const Col y = m.add_continuous(0.0, kInf, -1.0, "y");
  m.set_objective_offset(10.0);
  m.add_le({{x, 2.0}, {y, 3.0}}, 12.5, "budget");
  m.add_ge({{x, 1.0}, {y, -1.0}}, 0.5, "order");
  const SolveResult r = solve(m);
  expect_optimal(m, r, 23.0 / 6.0);
  EXPECT_EQ(r.solution[x], 6.0);
  EXPECT_NEAR(r.solution[y], 1.0 / 6.0, 1e-7);
  EXPECT_NEAR(r.best_bound, 23.0 / 6.0, 1e-4);  // the bound carries the offset too
}

TEST(IlpCbc, EqualityAndRangedRows) {
  // Pick exactly 3 of 5 (equality) with 1 <= x1 + x3 + x4 <= 2 (range), minimise c·x,
  // c = (3, -1, 2, -4, 1). The unconstrained best {1, 3, 4} breaks the range; {1, 2, 3} = -3.
  Model m;
  const std::array<double, 5> c{3, -1, 2, -4, 1};
  std::vector<Term> all;
  for (double ci : c) all.push_back({m.add_binary(ci), 1.0});
  m.add_eq(all, 3.0, "pick3");
  m.add_range(1.0, {{1, 1.0}, {3, 1.0}, {4, 1.0}}, 2.0, "band");
  ASSERT_EQ(enumerate_binary(m), -3.0);
  const SolveResult r = solve(m);
  expect_optimal(m, r, -3.0);
  EXPECT_EQ(r.solution, (std::vector<double>{0, 1, 1, 1, 0}));
}

TEST(IlpCbc, PureLp) {
  // min x + y s.t. x + 2y >= 2: y = 1, objective 1. No integer columns: no branch-and-bound and
  // no pre-processing, so the pre-solved size is unknown.
  Model m;
  const Col x = m.add_continuous(0.0, kInf, 1.0);
  const Col y = m.add_continuous(0.0, kInf, 1.0);
  m.add_ge({{x, 1.0}, {y, 2.0}}, 2.0);
  const SolveResult r = solve(m);
  expect_optimal(m, r, 1.0);
  EXPECT_EQ(r.presolved.rows, -1);
}

TEST(IlpCbc, InfeasibleLpRelaxation) {
  Model m;
  const Col x = m.add_binary(1.0), y = m.add_binary(1.0);
  m.add_ge({{x, 1.0}, {y, 1.0}}, 3.0, "impossible");
  const SolveResult r = solve(m);
  EXPECT_EQ(r.status, SolveStatus::Infeasible) << describe(r);
  EXPECT_FALSE(r.has_solution());
  EXPECT_EQ(r.objective, kInf);
  EXPECT_NE(r.call, CallStatus::Error) << r.message;
}

TEST(IlpCbc, IntegerInfeasibleWithFeasibleRelaxation) {
  // 2x + 2y = 3 has LP solutions but no integer ones. CBC's pre-processing proves it; we
  // re-check such claims without pre-processing (see cbc_solver.cpp), which must agree.
  Model m;
  const Col x = m.add_integer(0, 5, 1.0), y = m.add_integer(0, 5, 1.0);
  m.add_eq({{x, 2.0}, {y, 2.0}}, 3.0, "odd");
  const SolveResult r = solve(m);
  EXPECT_EQ(r.status, SolveStatus::Infeasible) << describe(r);
  EXPECT_FALSE(r.has_solution());
  EXPECT_NE(r.call, CallStatus::Error) << r.message;
}

TEST(IlpCbc, UnboundedRelaxation) {
  // min -x - y s.t. x - y <= 1, x integer >= 0, y >= 0: (x, y) = (t + 1, t) for any t.
  Model m;
  const Col x = m.add_integer(0, kInf, -1.0), y = m.add_continuous(0.0, kInf, -1.0);
  m.add_le({{x, 1.0}, {y, -1.0}}, 1.0);
  const SolveResult r = solve(m);
  EXPECT_EQ(r.status, SolveStatus::Unbounded) << describe(r);
  EXPECT_FALSE(r.has_solution());
}

TEST(IlpCbc, PresolvedSizeIsReported) {
  // x2 = 1 (singleton row) fixes x3 = 0 through x2 + x3 <= 1; pre-processing removes it all.
  Model m;
  const Col x0 = m.add_binary(-1), x1 = m.add_binary(-2), x2 = m.add_binary(-1), x3 = m.add_binary(-1);
  m.add_le({{x0, 1}, {x1, 1}}, 1);
  m.add_eq({{x2, 1}}, 1);
  m.add_le({{x2, 1}, {x3, 1}}, 1);
  m.add_le({{x0, 1}, {x1, 1}, {x2, 1}, {x3, 1}}, 3);
  const SolveResult r = solve(m);
  expect_optimal(m, r, -3.0);
  EXPECT_GE(r.presolved.rows, 0);
  EXPECT_LT(r.presolved.rows, r.built.rows);
  EXPECT_LE(r.presolved.cols, r.built.cols);
}

// ---------------------------------------------------------------------------------------------
// Oracle: random small binary programs against exhaustive enumeration.

TEST(IlpOracle, RandomBinaryProgramsMatchEnumeration) {
  std::mt19937 rng(20240611);
  int feasible = 0, infeasible = 0;
  for (int instance = 0; instance < 40; ++instance) {
    const int n = std::uniform_int_distribution<int>(3, 12)(rng);
    const int rows = std::uniform_int_distribution<int>(1, 6)(rng);
    std::uniform_int_distribution<int> coef(-5, 5), cost(-10, 10), kind(0, 3);
    Model m;
    for (int j = 0; j < n; ++j) m.add_binary(cost(rng));
    m.set_objective_offset(std::uniform_int_distribution<int>(-3, 3)(rng));
    for (int i = 0; i < rows; ++i) {
      std::vector<Term> row;
      double lo_sum = 0, hi_sum = 0;
      for (int j = 0; j < n; ++j) {
        const int a = coef(rng);
        if (a == 0 || std::uniform_int_distribution<int>(0, 2)(rng) == 0) continue;
        row.push_back({static_cast<Col>(j), static_cast<double>(a)});
        (a < 0 ? lo_sum : hi_sum) += a;
      }
      const int rhs = std::uniform_int_distribution<int>(static_cast<int>(lo_sum), static_cast<int>(hi_sum))(rng);
      switch (kind(rng)) {
        case 0: m.add_le(row, rhs); break;
        case 1: m.add_ge(row, rhs); break;
        case 2: m.add_eq(row, rhs); break;
        default: m.add_range(rhs - 1, row, rhs + 2); break;
      }
    }
    const std::optional<double> truth = enumerate_binary(m);
    SolveParams params = generous();
    params.seed = static_cast<std::uint32_t>(instance + 1);
    const SolveResult r = solve(m, params);
    SCOPED_TRACE(numbered("instance ", instance) + ": n=" + std::to_string(n) + " rows=" +
                 std::to_string(rows) + "\n" + m.to_lp_string());
    if (!truth) {
      ++infeasible;
      EXPECT_EQ(r.status, SolveStatus::Infeasible) << describe(r);
      EXPECT_FALSE(r.has_solution());
    } else {
      ++feasible;
      expect_optimal(m, r, *truth);
    }
  }
  // The generator must exercise both outcomes.
  EXPECT_GT(feasible, 10);
  EXPECT_GT(infeasible, 0);
}

// ---------------------------------------------------------------------------------------------
// MIP start

TEST(IlpCbc, MipStartIsAccepted) {
  Model m = random_knapsack(40, 5, 7);
  const std::vector<double> start = greedy_start(m);
  ASSERT_TRUE(m.is_feasible(start, 0.0));
  m.set_initial_solution(start);
  const SolveResult r = solve(m);
  ASSERT_TRUE(r.has_solution()) << describe(r);
  EXPECT_EQ(r.start, StartStatus::Accepted) << describe(r);
  EXPECT_TRUE(r.start_feasible);
  EXPECT_LE(r.objective, m.evaluate(start) + 1e-9);
  EXPECT_TRUE(m.is_feasible(r.solution));
}

TEST(IlpCbc, InfeasibleMipStartIsRejected) {
  Model m = random_knapsack(40, 5, 8);
  m.set_initial_solution(std::vector<double>(m.num_cols(), 1.0));  // everything: over capacity
  const SolveResult r = solve(m);
  EXPECT_EQ(r.start, StartStatus::Rejected) << describe(r);
  EXPECT_FALSE(r.start_feasible);
  EXPECT_FALSE(r.solution_is_start);
  EXPECT_TRUE(r.has_solution()) << describe(r);  // CBC still solves the model
}

TEST(IlpCbc, TimedOutSolveIsNeverWorseThanItsStart) {
  // A 300-item, 40-row knapsack cannot be finished in a few hundredths of a second; whatever
  // CBC does in that time (including pre-processing interrupted by the clock), the result must
  // carry a feasible solution at least as good as the start.
  Model m = random_knapsack(300, 40, 11);
  const std::vector<double> start = greedy_start(m);
  ASSERT_TRUE(m.is_feasible(start, 0.0));
  m.set_initial_solution(start);
  for (double limit : {0.001, 0.02}) {
    SolveParams params;
    params.time_limit_seconds = limit;
    const SolveResult r = solve(m, params);
    SCOPED_TRACE(numbered("time limit ", limit));
    EXPECT_EQ(r.status, SolveStatus::Feasible) << describe(r);
    ASSERT_TRUE(r.has_solution()) << describe(r);
    EXPECT_TRUE(m.is_feasible(r.solution)) << m.describe_violation(r.solution);
    EXPECT_LE(r.objective, m.evaluate(start) + 1e-9) << describe(r);
    EXPECT_TRUE(r.start_feasible);
    EXPECT_NE(r.start, StartStatus::Rejected) << describe(r);
  }
}

TEST(IlpCbc, RootLpCutShortByTheTimeLimitIsReported) {
  // 0.1 ms is far less than loading and solving this LP takes; CBC's own limit does not cover
  // the root LP, Clp's wall-clock limit (set by the backend) does.
  const Model m = random_knapsack(300, 40, 13);
  SolveParams params;
  params.time_limit_seconds = 1e-4;
  const SolveResult r = solve(m, params);
  EXPECT_EQ(r.status, SolveStatus::NoSolution) << describe(r);
  EXPECT_FALSE(r.has_solution());
  EXPECT_EQ(r.call, CallStatus::Warning) << describe(r);
  EXPECT_NE(r.message.find("root LP"), std::string::npos) << r.message;
  EXPECT_EQ(r.best_bound, -kInf);  // an interrupted simplex proves no bound
  EXPECT_EQ(r.presolved.rows, -1);
}

TEST(IlpCbc, StartCanServeAsFloorOnly) {
  const Model m = knapsack_with_floor(12);
  SolveParams params;
  params.time_limit_seconds = 0.02;
  params.start_as_mip_start = false;
  const SolveResult r = solve(m, params);
  EXPECT_EQ(r.start, StartStatus::NotUsed);
  EXPECT_TRUE(r.start_feasible);
  EXPECT_EQ(r.status, SolveStatus::Feasible) << describe(r);
  expect_start_is_the_floor(m, r);
}

TEST(IlpCbc, StallStopsTheSearchWithoutClaimingOptimality) {
  // With a 1 ms stall limit the search stops at the first node that follows a millisecond
  // without a better incumbent, long before the (generous) time limit and without a proof.
  const Model m = knapsack_with_floor(14);
  SolveParams params;
  params.time_limit_seconds = 600.0;
  params.stall_seconds = 1e-3;
  params.start_as_mip_start = false;
  const SolveResult r = solve(m, params);
  EXPECT_TRUE(r.stalled) << describe(r);
  EXPECT_EQ(r.status, SolveStatus::Feasible) << describe(r);
  expect_start_is_the_floor(m, r);
  EXPECT_GT(r.gap, 0.0);
}

TEST(IlpCbc, StartSurvivesInvalidParameters) {
  Model m = random_knapsack(20, 3, 5);
  const std::vector<double> start = greedy_start(m);
  m.set_initial_solution(start);
  SolveParams params;
  params.time_limit_seconds = 0.0;  // invalid
  const SolveResult r = solve(m, params);
  EXPECT_EQ(r.call, CallStatus::Error);
  EXPECT_NE(r.message.find("time_limit_seconds"), std::string::npos) << r.message;
  EXPECT_EQ(r.status, SolveStatus::Feasible);
  EXPECT_TRUE(r.solution_is_start);
  EXPECT_EQ(r.solution, start);
}

TEST(IlpCbc, StartOfWrongSizeIsIgnored) {
  Model m = random_knapsack(20, 3, 6);
  m.set_initial_solution(greedy_start(m));
  m.add_binary(-1000.0, "added_after_the_start");
  const SolveResult r = solve(m);
  EXPECT_EQ(r.start, StartStatus::WrongSize);
  EXPECT_EQ(r.call, CallStatus::Warning);
  expect_optimal(m, r, r.objective);
  EXPECT_EQ(r.solution.back(), 1.0);
}

// ---------------------------------------------------------------------------------------------
// Parameters, progress, factory

TEST(IlpCbc, ProgressReportsImprovingIncumbents) {
  Model m = random_knapsack(120, 20, 3);
  m.set_objective_offset(1e5);  // progress values must include it
  std::vector<Progress> seen;
  SolveParams params;
  params.time_limit_seconds = 2.0;
  params.on_progress = [&](const Progress& p) { seen.push_back(p); };
  const SolveResult r = solve(m, params);
  ASSERT_TRUE(r.has_solution()) << describe(r);
  ASSERT_FALSE(seen.empty());
  for (std::size_t i = 0; i < seen.size(); ++i) {
    EXPECT_GE(seen[i].objective, r.objective - 1e-6) << i;
    EXPECT_GT(seen[i].objective, 0.0) << i;  // offset included (the values are ~1e5 - 3000)
    if (i > 0) {
      EXPECT_LT(seen[i].objective, seen[i - 1].objective) << i;
      EXPECT_GE(seen[i].seconds, seen[i - 1].seconds) << i;
    }
  }
  EXPECT_NEAR(seen.back().objective, r.objective, 1e-6);
}

TEST(IlpCbc, ThreadsAndSeedsGiveTheSameOptimum) {
  Model m = random_knapsack(30, 4, 21);
  const SolveResult a = solve(m, generous());
  SolveParams many = generous();
  many.threads = 2;
  many.seed = 12345;
  const SolveResult b = solve(m, many);
  SolveParams hardware = generous();
  hardware.threads = 0;
  const SolveResult c = solve(m, hardware);
  ASSERT_EQ(a.status, SolveStatus::Optimal) << describe(a);
  expect_optimal(m, b, a.objective);
  expect_optimal(m, c, a.objective);
}

TEST(IlpCbc, InvalidParametersAreReported) {
  Model m;
  m.add_binary(1.0);
  for (auto bad : {+[](SolveParams& p) { p.time_limit_seconds = -1; },
                   +[](SolveParams& p) { p.time_limit_seconds = std::nan(""); },
                   +[](SolveParams& p) { p.threads = -2; },
                   +[](SolveParams& p) { p.relative_gap = -0.1; },
                   +[](SolveParams& p) { p.stall_seconds = 0.0; }}) {
    SolveParams p;
    bad(p);
    const SolveResult r = solve(m, p);
    EXPECT_EQ(r.call, CallStatus::Error);
    EXPECT_EQ(r.status, SolveStatus::Error);
    EXPECT_FALSE(r.has_solution());
  }
  SolveParams unlimited;
  unlimited.time_limit_seconds = kInf;
  expect_optimal(m, solve(m, unlimited), 0.0);
}

TEST(IlpCbc, SilentUnlessAskedToLog) {
  // CBC prints through printf, std::cout and its message handlers; none of it may reach the
  // CLI's stdout/stderr at log_level 0, whatever path the solve takes.
  Model knapsack = random_knapsack(60, 6, 4);
  knapsack.set_initial_solution(greedy_start(knapsack));
  Model odd;
  const Col x = odd.add_integer(0, 5, 1.0), y = odd.add_integer(0, 5, 1.0);
  odd.add_eq({{x, 2.0}, {y, 2.0}}, 3.0);
  SolveParams threaded = generous();
  threaded.threads = 2;
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  const SolveResult a = solve(knapsack, threaded);
  const SolveResult b = solve(odd);
  SolveParams tiny;
  tiny.time_limit_seconds = 1e-4;
  const SolveResult c = solve(knapsack, tiny);
  const std::string out = testing::internal::GetCapturedStdout();
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "");
  EXPECT_EQ(a.status, SolveStatus::Optimal) << describe(a);
  EXPECT_EQ(b.status, SolveStatus::Infeasible) << describe(b);
  EXPECT_TRUE(c.has_solution()) << describe(c);
}

TEST(IlpSolverFactory, KnowsCbcAndListsBackendsForUnknownNames) {
  auto cbc = make_solver("cbc");
  ASSERT_NE(cbc, nullptr);
  EXPECT_EQ(cbc->name(), "cbc");
  EXPECT_EQ(available_solvers(), std::vector<std::string>{"cbc"});
  std::string error;
  EXPECT_EQ(make_solver("gurobi", &error), nullptr);
  EXPECT_NE(error.find("gurobi"), std::string::npos) << error;
  EXPECT_NE(error.find("cbc"), std::string::npos) << error;
  EXPECT_EQ(make_solver("CBC"), nullptr);
}

}  // namespace

TEST(IlpCbc, StartAsCutoffProvenOptimal) {
  // minimise -x0 - x1/2 subject to x0 + x1 <= 1: the start (1, 0) is the unique optimum.
  // Handed over as a cutoff, CBC finds nothing better; the finished search proves it optimal.
  Model m;
  const Col x0 = m.add_binary(-1.0);
  const Col x1 = m.add_binary(-0.5);
  m.add_le({{x0, 1.0}, {x1, 1.0}}, 1.0);
  m.set_initial_solution({1.0, 0.0});
  SolveParams params;
  params.time_limit_seconds = 30.0;
  params.start_as_mip_start = false;
  const SolveResult r = solve(m, params);
  EXPECT_EQ(r.start, StartStatus::NotUsed);
  EXPECT_EQ(r.status, SolveStatus::Optimal) << describe(r);
  ASSERT_TRUE(r.has_solution());
  EXPECT_DOUBLE_EQ(r.objective, -1.0);
  EXPECT_EQ(r.solution, (std::vector<double>{1.0, 0.0}));
}

TEST(IlpModel, WithoutFixedColumnsMovesConstantsIntoRowsAndOffset) {
  // min 2a + 3b + c  s.t.  a + b + c >= 2,  b - c <= 0,  a fixed at 1.
  Model m;
  const Col a = m.add_binary(2.0);
  const Col b = m.add_binary(3.0);
  const Col c = m.add_binary(1.0);
  m.set_bounds(a, 1.0, 1.0);
  m.add_ge({{a, 1.0}, {b, 1.0}, {c, 1.0}}, 2.0);
  m.add_le({{b, 1.0}, {c, -1.0}}, 0.0);
  m.add_le({{a, 1.0}}, 1.0);  // constant after substitution: dropped, satisfied
  m.set_initial_solution({1.0, 1.0, 1.0});
  const ReducedModel r = without_fixed_columns(m);
  ASSERT_EQ(r.model.num_cols(), 2u);
  EXPECT_EQ(r.kept, (std::vector<Col>{b, c}));
  EXPECT_EQ(r.model.num_rows(), 2u);
  EXPECT_EQ(r.violated_constant_rows, 0u);
  EXPECT_DOUBLE_EQ(r.model.objective_offset(), 2.0);
  EXPECT_DOUBLE_EQ(r.model.row_lower(0), 1.0);  // b + c >= 2 - 1
  EXPECT_EQ(r.model.initial_solution(), (std::vector<double>{1.0, 1.0}));
  // Same optimum through the reduced model: b = 0, c = 1, objective 2 + 1 = 3.
  SolveParams params;
  params.time_limit_seconds = 10;
  const SolveResult s = solve(r.model, params);
  ASSERT_EQ(s.status, SolveStatus::Optimal) << describe(s);
  EXPECT_DOUBLE_EQ(s.objective, 3.0);
  const std::vector<double> x = r.expand(m, s.solution);
  EXPECT_EQ(x, (std::vector<double>{1.0, 0.0, 1.0}));
  EXPECT_DOUBLE_EQ(m.evaluate(x), 3.0);
  // A fixed column that breaks a row is reported.
  Model bad;
  const Col z = bad.add_binary();
  bad.set_bounds(z, 0.0, 0.0);
  bad.add_ge({{z, 1.0}}, 1.0);
  EXPECT_EQ(without_fixed_columns(bad).violated_constant_rows, 1u);
}
