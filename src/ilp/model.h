// quadlod — solver-neutral mixed-integer linear model.
//
// The formulation of the paper (§3.2, Eqs. 1–9: one binary per edge and per face, continuous
// cluster indicators, face-count and consistency rows) is built into this Model and handed to a
// backend (src/ilp/solver.h). Nothing here knows about CBC or any other solver, so a new backend
// reads the same arrays.
//
//     minimise   c·x + objective_offset
//     subject to row_lower[r] <= sum_k a_rk x_k <= row_upper[r]   for every row r
//                col_lower[j] <= x_j <= col_upper[j]               for every column j
//                x_j integral                                      for Binary / Integer columns
//
// Storage is flat: per-column parallel arrays, and the matrix as row-major CSR (row_start,
// row_cols, row_coefs) that rows are appended to. A model with 100k+ rows costs a few vectors,
// no per-row allocation. Names are optional and kept in one character pool per kind; a model
// in which nothing is named stores no names at all.
//
// Contract violations while building (index out of range, NaN or infinite coefficients,
// lower > upper, binary bounds outside [0,1]) are programming errors in the formulation and
// throw std::invalid_argument naming the offending column or row. Nothing else throws.
#pragma once

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace quadlod::ilp {

/// Column (variable) and row (constraint) ids: dense, 0-based, in order of creation.
using Col = std::uint32_t;
using Row = std::uint32_t;

/// The value used for "no bound". Rows and columns accept ±kInf for one-sided bounds.
inline constexpr double kInf = std::numeric_limits<double>::infinity();

enum class VarType : std::uint8_t {
  Binary,      ///< integral, bounds within [0, 1] (default exactly [0, 1])
  Integer,     ///< integral, any bounds (may be infinite)
  Continuous,  ///< real, any bounds (may be infinite)
};

/// One entry a_rk x_k of a linear row.
struct Term {
  Col col;
  double coef;
};

/// Row and column counts of a model (or of a solver's pre-processed copy of it).
/// -1 means "not known" (a backend that cannot report the size of its pre-processed model).
struct ModelSize {
  std::int64_t rows = -1;
  std::int64_t cols = -1;
  std::int64_t nonzeros = -1;
  std::int64_t integer_cols = -1;  ///< Binary + Integer columns
};

class Model {
 public:
  // --- building --------------------------------------------------------------------------

  /// Optional capacity hints; building works without them.
  void reserve(std::size_t cols, std::size_t rows, std::size_t nonzeros);

  /// Adds a column with bounds [lower, upper] and objective coefficient `objective`.
  /// Preconditions: lower <= upper, neither NaN, lower < +inf, upper > -inf, objective finite;
  /// Binary columns need 0 <= lower <= upper <= 1. `name` may be empty (LP output then uses
  /// "x<id>"). Returns the new column id (== num_cols() before the call).
  Col add_var(VarType type, double lower, double upper, double objective = 0.0,
              std::string_view name = {});
  Col add_binary(double objective = 0.0, std::string_view name = {}) {
    return add_var(VarType::Binary, 0.0, 1.0, objective, name);
  }
  Col add_integer(double lower, double upper, double objective = 0.0, std::string_view name = {}) {
    return add_var(VarType::Integer, lower, upper, objective, name);
  }
  Col add_continuous(double lower, double upper, double objective = 0.0,
                     std::string_view name = {}) {
    return add_var(VarType::Continuous, lower, upper, objective, name);
  }

  /// Adds the row  lower <= sum terms <= upper  (use ±kInf for a one-sided row).
  /// Terms naming the same column are merged (coefficients summed); terms whose coefficient is
  /// (or sums to) exactly 0 are dropped; the stored row is sorted by column. A row may end up
  /// empty (then it is a pure bound check 0 in [lower, upper]).
  /// Preconditions: every col < num_cols(), coefficients finite, lower <= upper, neither NaN,
  /// lower < +inf, upper > -inf. Returns the new row id.
  Row add_range(double lower, std::span<const Term> terms, double upper, std::string_view name = {});
  Row add_le(std::span<const Term> terms, double rhs, std::string_view name = {}) {
    return add_range(-kInf, terms, rhs, name);
  }
  Row add_ge(std::span<const Term> terms, double rhs, std::string_view name = {}) {
    return add_range(rhs, terms, kInf, name);
  }
  Row add_eq(std::span<const Term> terms, double rhs, std::string_view name = {}) {
    return add_range(rhs, terms, rhs, name);
  }
  // Brace-list convenience: model.add_le({{x, 1}, {y, 2}}, 3, "cap").
  Row add_range(double lower, std::initializer_list<Term> terms, double upper,
                std::string_view name = {}) {
    return add_range(lower, std::span<const Term>(terms.begin(), terms.size()), upper, name);
  }
  Row add_le(std::initializer_list<Term> terms, double rhs, std::string_view name = {}) {
    return add_range(-kInf, terms, rhs, name);
  }
  Row add_ge(std::initializer_list<Term> terms, double rhs, std::string_view name = {}) {
    return add_range(rhs, terms, kInf, name);
  }
  Row add_eq(std::initializer_list<Term> terms, double rhs, std::string_view name = {}) {
    return add_range(rhs, terms, rhs, name);
  }

  /// Objective coefficient of `col` (replaces / accumulates). Precondition: finite value.
  void set_objective(Col col, double coef);
  void add_objective(Col col, double delta);
  /// Constant added to the objective (reported objectives and bounds include it).
  void set_objective_offset(double offset);
  /// Changes the bounds of an existing column (same preconditions as add_var).
  void set_bounds(Col col, double lower, double upper);

  /// Optional MIP start: one value per column (size must equal num_cols() now and when the
  /// model is solved; a start whose size no longer matches is ignored by the backends and
  /// reported as StartStatus::WrongSize). It need not be feasible; backends may complete or
  /// reject it. Pass an empty vector to clear.
  void set_initial_solution(std::vector<double> values);
  const std::vector<double>& initial_solution() const { return initial_solution_; }
  bool has_initial_solution() const { return !initial_solution_.empty(); }

  // --- reading -----------------------------------------------------------------------------

  Col num_cols() const { return static_cast<Col>(col_type_.size()); }
  Row num_rows() const { return static_cast<Row>(row_lower_.size()); }
  std::size_t num_nonzeros() const { return row_cols_.size(); }
  std::size_t num_integer_cols() const { return num_integer_; }
  ModelSize size() const;

  VarType col_type(Col c) const { return col_type_[c]; }
  bool is_integer(Col c) const { return col_type_[c] != VarType::Continuous; }
  double col_lower(Col c) const { return col_lower_[c]; }
  double col_upper(Col c) const { return col_upper_[c]; }
  double objective(Col c) const { return objective_[c]; }
  double objective_offset() const { return objective_offset_; }
  /// The name given at creation, or "" if none.
  std::string_view col_name(Col c) const;

  double row_lower(Row r) const { return row_lower_[r]; }
  double row_upper(Row r) const { return row_upper_[r]; }
  std::span<const Col> row_cols(Row r) const {
    return {row_cols_.data() + row_start_[r], row_cols_.data() + row_start_[r + 1]};
  }
  std::span<const double> row_coefs(Row r) const {
    return {row_coefs_.data() + row_start_[r], row_coefs_.data() + row_start_[r + 1]};
  }
  std::string_view row_name(Row r) const;

  // Bulk access for backends (parallel arrays; the matrix is CSR with num_rows()+1 starts).
  std::span<const VarType> col_types() const { return col_type_; }
  std::span<const double> col_lowers() const { return col_lower_; }
  std::span<const double> col_uppers() const { return col_upper_; }
  std::span<const double> objectives() const { return objective_; }
  std::span<const double> row_lowers() const { return row_lower_; }
  std::span<const double> row_uppers() const { return row_upper_; }
  std::span<const std::uint32_t> row_starts() const { return row_start_; }
  std::span<const Col> matrix_cols() const { return row_cols_; }
  std::span<const double> matrix_coefs() const { return row_coefs_; }

  // --- checking solutions ------------------------------------------------------------------

  /// c·x + objective_offset. Returns NaN if x.size() != num_cols().
  double evaluate(std::span<const double> x) const;

  /// Largest absolute violation over all column bounds, integrality (|x - round(x)| of
  /// Binary/Integer columns) and rows (distance of the row activity from [lower, upper]).
  /// 0 for a feasible point. +inf if x.size() != num_cols() or x holds NaN/inf.
  /// Absolute, not scaled: callers choose a tolerance that suits their coefficients.
  double max_violation(std::span<const double> x) const;

  /// max_violation(x) <= tol.
  bool is_feasible(std::span<const double> x, double tol = 1e-6) const {
    return max_violation(x) <= tol;
  }

  /// A one-line description of the worst violation, e.g.
  /// "row 'cover_3' activity 0 below lower bound 1 (violation 1)"; empty if max_violation <= tol.
  std::string describe_violation(std::span<const double> x, double tol = 1e-6) const;

  // --- output ------------------------------------------------------------------------------

  /// Writes the model in CPLEX LP format for debugging and for feeding other solvers.
  /// Names are the given ones (characters the format does not allow become '_', clashing or
  /// missing names get "x<id>" / "r<id>"-style names); ranged rows (both bounds finite and
  /// different) are written as two rows "<name>_lo" and "<name>_hi"; free rows are written as
  /// comments; the objective offset is written as a constant term of the objective.
  /// Returns "" on success, otherwise "<path>: <reason>". Not atomic: a failed write may leave
  /// a partial file.
  [[nodiscard]] std::string write_lp(const std::filesystem::path& path) const;

  /// The same text as write_lp, in memory.
  std::string to_lp_string() const;

 private:
  // A pool of optional names: offsets_ is empty until the first name arrives, then holds
  // count+1 offsets into chars_ (unnamed entries have an empty range).
  struct NamePool {
    std::string chars;
    std::vector<std::uint32_t> offsets;
    void add(std::string_view name, std::size_t index);
    std::string_view get(std::size_t index) const;
  };

  void check_col(Col c, const char* what) const;

  std::vector<VarType> col_type_;
  std::vector<double> col_lower_, col_upper_, objective_;
  NamePool col_names_;
  std::size_t num_integer_ = 0;

  std::vector<double> row_lower_, row_upper_;
  std::vector<std::uint32_t> row_start_{0};
  std::vector<Col> row_cols_;
  std::vector<double> row_coefs_;
  NamePool row_names_;

  double objective_offset_ = 0.0;
  std::vector<double> initial_solution_;

  std::vector<Term> scratch_;  // add_range's sort buffer, kept to avoid a per-row allocation
};

}  // namespace quadlod::ilp

namespace quadlod::ilp {

/// A model with its fixed columns (lower == upper) substituted out: their contribution moves to
/// the row bounds and the objective offset, rows left without a column are dropped. Backends
/// would presolve them away too, but loading and presolving tens of thousands of fixed columns
/// costs more than solving a small neighbourhood (the large-neighbourhood search of
/// src/select/neighbourhoods.cpp solves such models by the hundred).
struct ReducedModel {
  Model model;
  std::vector<Col> kept;         ///< reduced column → original column
  Row violated_constant_rows = 0;  ///< dropped rows whose constant violates their bounds
  /// The original column vector for a reduced solution (fixed columns at their value).
  std::vector<double> expand(const Model& original, const std::vector<double>& reduced) const;
};
ReducedModel without_fixed_columns(const Model& model, double tolerance = 1e-9);

}  // namespace quadlod::ilp
