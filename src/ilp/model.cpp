// quadlod — solver-neutral MIP model: building, checking solutions, CPLEX LP output.
// See model.h for the contract. The formulation (paper §3.2, Eqs. 1–9) lives elsewhere and only
// appends to this model.
#include "ilp/model.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <unordered_set>

namespace quadlod::ilp {

namespace {

std::string num(double v) {
  if (std::isinf(v)) return v > 0 ? "+inf" : "-inf";
  char buf[32];
  // Shortest text that reads back to the same double: the LP file is exact.
  auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), v);
  return ec == std::errc{} ? std::string(buf, end) : std::string("nan");
}

[[noreturn]] void fail(const std::string& what) { throw std::invalid_argument("ilp::Model: " + what); }

// `what()` names the column or row; it is only called on failure (building the text for every
// column and row cost more than the rest of add_var / add_range on neighbourhood models).
template <class What>
void check_bounds(double lower, double upper, const What& what) {
  if (std::isnan(lower) || std::isnan(upper)) fail(what() + ": NaN bound");
  if (lower == kInf || upper == -kInf)
    fail(what() + ": bounds [" + num(lower) + ", " + num(upper) + "] admit no finite value");
  if (lower > upper) fail(what() + ": lower bound " + num(lower) + " > upper bound " + num(upper));
}

}  // namespace

// --- names ---------------------------------------------------------------------------------

void Model::NamePool::add(std::string_view name, std::size_t index) {
  if (offsets.empty()) {
    if (name.empty()) return;  // still nothing named: store nothing
    offsets.assign(index + 1, 0);
  }
  if (chars.size() + name.size() > UINT32_MAX) throw std::length_error("ilp::Model: name pool full");
  chars.append(name);
  offsets.push_back(static_cast<std::uint32_t>(chars.size()));
}

std::string_view Model::NamePool::get(std::size_t index) const {
  if (offsets.empty()) return {};
  return std::string_view(chars).substr(offsets[index], offsets[index + 1] - offsets[index]);
}

std::string_view Model::col_name(Col c) const { return col_names_.get(c); }
std::string_view Model::row_name(Row r) const { return row_names_.get(r); }

// --- building ------------------------------------------------------------------------------

void Model::reserve(std::size_t cols, std::size_t rows, std::size_t nonzeros) {
  col_type_.reserve(cols);
  col_lower_.reserve(cols);
  col_upper_.reserve(cols);
  objective_.reserve(cols);
  row_lower_.reserve(rows);
  row_upper_.reserve(rows);
  row_start_.reserve(rows + 1);
  row_cols_.reserve(nonzeros);
  row_coefs_.reserve(nonzeros);
}

void Model::check_col(Col c, const char* what) const {
  if (c >= num_cols())
    fail(std::string(what) + ": column " + std::to_string(c) + " out of range (" +
         std::to_string(num_cols()) + " columns)");
}

Col Model::add_var(VarType type, double lower, double upper, double objective,
                   std::string_view name) {
  const Col c = num_cols();
  // Backends index columns with int (COIN's CoinBigIndex is 32-bit signed).
  if (c >= static_cast<Col>(INT32_MAX)) fail("too many columns");
  auto what = [&] { return "column " + std::to_string(c) + (name.empty() ? "" : " '" + std::string(name) + "'"); };
  check_bounds(lower, upper, what);
  if (type == VarType::Binary && (lower < 0.0 || upper > 1.0))
    fail(what() + ": binary bounds [" + num(lower) + ", " + num(upper) + "] outside [0, 1]");
  if (!std::isfinite(objective)) fail(what() + ": objective coefficient " + num(objective));
  col_type_.push_back(type);
  col_lower_.push_back(lower);
  col_upper_.push_back(upper);
  objective_.push_back(objective);
  col_names_.add(name, c);
  if (type != VarType::Continuous) ++num_integer_;
  return c;
}

Row Model::add_range(double lower, std::span<const Term> terms, double upper,
                     std::string_view name) {
  const Row r = num_rows();
  if (r >= static_cast<Row>(INT32_MAX)) fail("too many rows");
  if (row_cols_.size() + terms.size() >= static_cast<std::size_t>(INT32_MAX))
    fail("too many nonzeros");
  auto what = [&] {
    return "row " + std::to_string(r) + (name.empty() ? "" : " '" + std::string(name) + "'");
  };
  check_bounds(lower, upper, what);
  for (const Term& t : terms) {
    if (t.col >= num_cols()) check_col(t.col, what().c_str());
    if (!std::isfinite(t.coef)) fail(what() + ": coefficient " + num(t.coef) + " of column " + std::to_string(t.col));
  }

  // Canonical form: sorted by column, duplicates merged, zeros dropped. Backends (CoinPackedMatrix
  // among them) reject or mis-handle duplicate entries, and a canonical row makes LP output and
  // tests deterministic. Rows of the formulation are short, so sorting them costs nothing.
  scratch_.assign(terms.begin(), terms.end());
  const auto by_col = [](const Term& a, const Term& b) { return a.col < b.col; };
  if (!std::is_sorted(scratch_.begin(), scratch_.end(), by_col))
    std::stable_sort(scratch_.begin(), scratch_.end(), by_col);
  for (std::size_t i = 0; i < scratch_.size();) {
    const Col c = scratch_[i].col;
    double sum = 0.0;
    for (; i < scratch_.size() && scratch_[i].col == c; ++i) sum += scratch_[i].coef;
    if (sum != 0.0) {
      row_cols_.push_back(c);
      row_coefs_.push_back(sum);
    }
  }
  row_start_.push_back(static_cast<std::uint32_t>(row_cols_.size()));
  row_lower_.push_back(lower);
  row_upper_.push_back(upper);
  row_names_.add(name, r);
  return r;
}

void Model::set_objective(Col col, double coef) {
  check_col(col, "set_objective");
  if (!std::isfinite(coef)) fail("set_objective: coefficient " + num(coef));
  objective_[col] = coef;
}

void Model::add_objective(Col col, double delta) {
  check_col(col, "add_objective");
  if (!std::isfinite(delta)) fail("add_objective: coefficient " + num(delta));
  objective_[col] += delta;
}

void Model::set_objective_offset(double offset) {
  if (!std::isfinite(offset)) fail("objective offset " + num(offset));
  objective_offset_ = offset;
}

void Model::set_bounds(Col col, double lower, double upper) {
  check_col(col, "set_bounds");
  auto what = [&] { return "set_bounds of column " + std::to_string(col); };
  check_bounds(lower, upper, what);
  if (col_type_[col] == VarType::Binary && (lower < 0.0 || upper > 1.0))
    fail(what() + ": binary bounds [" + num(lower) + ", " + num(upper) + "] outside [0, 1]");
  col_lower_[col] = lower;
  col_upper_[col] = upper;
}

void Model::set_initial_solution(std::vector<double> values) {
  if (!values.empty() && values.size() != num_cols())
    fail("initial solution has " + std::to_string(values.size()) + " values for " +
         std::to_string(num_cols()) + " columns");
  initial_solution_ = std::move(values);
}

ModelSize Model::size() const {
  return {static_cast<std::int64_t>(num_rows()), static_cast<std::int64_t>(num_cols()),
          static_cast<std::int64_t>(num_nonzeros()), static_cast<std::int64_t>(num_integer_)};
}

// --- checking solutions --------------------------------------------------------------------

double Model::evaluate(std::span<const double> x) const {
  if (x.size() != num_cols()) return std::numeric_limits<double>::quiet_NaN();
  double sum = objective_offset_;
  for (Col c = 0; c < num_cols(); ++c) sum += objective_[c] * x[c];
  return sum;
}

namespace {

// The worst violation found while scanning, with enough context to describe it.
struct Worst {
  double amount = 0.0;
  enum Kind { None, BadSize, NotFinite, ColLower, ColUpper, Integrality, RowLower, RowUpper } kind = None;
  std::uint32_t index = 0;
  double value = 0.0, bound = 0.0;

  void offer(double a, Kind k, std::uint32_t i, double v, double b) {
    if (a > amount) *this = {a, k, i, v, b};
  }
};

Worst scan(const Model& m, std::span<const double> x) {
  Worst w;
  if (x.size() != m.num_cols()) {
    w.amount = kInf;
    w.kind = Worst::BadSize;
    return w;
  }
  for (Col c = 0; c < m.num_cols(); ++c) {
    const double v = x[c];
    if (!std::isfinite(v)) {
      w = {kInf, Worst::NotFinite, c, v, 0.0};
      return w;
    }
    w.offer(m.col_lower(c) - v, Worst::ColLower, c, v, m.col_lower(c));
    w.offer(v - m.col_upper(c), Worst::ColUpper, c, v, m.col_upper(c));
    if (m.is_integer(c)) w.offer(std::abs(v - std::round(v)), Worst::Integrality, c, v, std::round(v));
  }
  for (Row r = 0; r < m.num_rows(); ++r) {
    const auto cols = m.row_cols(r);
    const auto coefs = m.row_coefs(r);
    double activity = 0.0;
    for (std::size_t k = 0; k < cols.size(); ++k) activity += coefs[k] * x[cols[k]];
    w.offer(m.row_lower(r) - activity, Worst::RowLower, r, activity, m.row_lower(r));
    w.offer(activity - m.row_upper(r), Worst::RowUpper, r, activity, m.row_upper(r));
  }
  return w;
}

}  // namespace

double Model::max_violation(std::span<const double> x) const { return scan(*this, x).amount; }

std::string Model::describe_violation(std::span<const double> x, double tol) const {
  const Worst w = scan(*this, x);
  if (w.amount <= tol) return {};
  auto col = [&](std::uint32_t c) {
    const auto n = col_name(c);
    return "column " + std::to_string(c) + (n.empty() ? "" : " '" + std::string(n) + "'");
  };
  auto row = [&](std::uint32_t r) {
    const auto n = row_name(r);
    return "row " + std::to_string(r) + (n.empty() ? "" : " '" + std::string(n) + "'");
  };
  const std::string by = " (violation " + num(w.amount) + ")";
  switch (w.kind) {
    case Worst::BadSize:
      return "solution has " + std::to_string(x.size()) + " values for " + std::to_string(num_cols()) + " columns";
    case Worst::NotFinite: return col(w.index) + " has non-finite value " + num(w.value);
    case Worst::ColLower: return col(w.index) + " value " + num(w.value) + " below lower bound " + num(w.bound) + by;
    case Worst::ColUpper: return col(w.index) + " value " + num(w.value) + " above upper bound " + num(w.bound) + by;
    case Worst::Integrality: return col(w.index) + " value " + num(w.value) + " is not integral" + by;
    case Worst::RowLower: return row(w.index) + " activity " + num(w.value) + " below lower bound " + num(w.bound) + by;
    case Worst::RowUpper: return row(w.index) + " activity " + num(w.value) + " above upper bound " + num(w.bound) + by;
    case Worst::None: break;
  }
  return {};
}

// --- CPLEX LP output -----------------------------------------------------------------------

namespace {

// CPLEX LP names: at most 255 characters from a restricted set, not starting with a digit or a
// period, and not looking like an exponent ("e", "e12", "E9x"...). We keep a conservative subset
// of the allowed characters so that every LP reader we know (CPLEX, CoinLpIO, HiGHS, Gurobi)
// parses the file; anything else becomes '_'.
std::string sanitize(std::string_view in) {
  std::string s;
  s.reserve(in.size() + 1);
  for (char ch : in) {
    const bool ok = std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '.' || ch == '#';
    s.push_back(ok ? ch : '_');
  }
  if (!s.empty()) {
    const char c0 = s[0];
    const bool looks_numeric = std::isdigit(static_cast<unsigned char>(c0)) || c0 == '.';
    const bool looks_exponent =
        (c0 == 'e' || c0 == 'E') &&
        (s.size() == 1 || std::isdigit(static_cast<unsigned char>(s[1])) || s[1] == 'e' || s[1] == 'E');
    if (looks_numeric || looks_exponent) s.insert(s.begin(), '_');
  }
  if (s.size() > 240) s.resize(240);  // leaves room for a uniqueness suffix within 255
  return s;
}

// Hands out names that are unique within one namespace (columns, or rows).
class UniqueNames {
 public:
  std::string take(std::string name, const std::string& fallback) {
    if (name.empty()) name = fallback;
    if (seen_.insert(name).second) return name;
    for (int k = 1;; ++k) {
      std::string alt = name + "_" + std::to_string(k);
      if (seen_.insert(alt).second) return alt;
    }
  }

 private:
  std::unordered_set<std::string> seen_;
};

// Appends " + 3 x" style terms, breaking lines well before the 510-character limit of CPLEX.
class LineWriter {
 public:
  explicit LineWriter(std::string& out) : out_(out) {}
  void start(const std::string& head) {
    out_ += head;
    line_start_ = out_.size() - head.size();
    first_ = true;
  }
  void term(double coef, const std::string& name) {
    if (out_.size() - line_start_ > 200) {
      out_ += "\n   ";
      line_start_ = out_.size() - 3;
    }
    if (coef < 0) {
      out_ += first_ ? " -" : " - ";
      coef = -coef;
    } else if (!first_) {
      out_ += " + ";
    } else {
      out_ += " ";
    }
    if (coef != 1.0) {
      out_ += num(coef);
      out_ += ' ';
    }
    out_ += name;
    first_ = false;
  }
  void constant(double v) {
    if (v == 0.0) return;
    out_ += v < 0 ? " - " : " + ";
    out_ += num(std::abs(v));
    first_ = false;
  }
  bool empty() const { return first_; }

 private:
  std::string& out_;
  std::size_t line_start_ = 0;
  bool first_ = true;
};

// "x12" / "r7". Built by appending: GCC 12 warns (-Wrestrict, a known false positive, GCC bug
// 105651) about `"x" + std::to_string(i)`.
std::string default_name(char prefix, std::size_t index) {
  std::string s(1, prefix);
  s += std::to_string(index);
  return s;
}

}  // namespace

std::string Model::to_lp_string() const {
  const Col n = num_cols();
  std::vector<std::string> cname(n);
  {
    UniqueNames unique;
    for (Col c = 0; c < n; ++c) cname[c] = unique.take(sanitize(col_name(c)), default_name('x', c));
  }

  std::string out;
  out.reserve(64 + 24 * (num_nonzeros() + n) + 32 * num_rows());
  out += "\\ quadlod ILP model (quadlod::ilp::Model::write_lp)\n";
  out += "\\ " + std::to_string(n) + " columns (" + std::to_string(num_integer_) + " integer), " +
         std::to_string(num_rows()) + " rows, " + std::to_string(num_nonzeros()) + " nonzeros\n";
  if (objective_offset_ != 0.0) out += "\\ objective offset " + num(objective_offset_) + "\n";

  LineWriter w(out);
  out += "Minimize\n";
  w.start(" obj:");
  for (Col c = 0; c < n; ++c)
    if (objective_[c] != 0.0) w.term(objective_[c], cname[c]);
  // LP readers expect at least one variable in the objective; "0 x0" is the neutral one.
  if (w.empty() && n > 0) w.term(0.0, cname[0]);
  w.constant(objective_offset_);
  out += "\nSubject To\n";

  UniqueNames unique_rows;
  auto write_row = [&](const std::string& name, Row r, const char* sense, double rhs) {
    w.start(" " + name + ":");
    const auto cols = row_cols(r);
    const auto coefs = row_coefs(r);
    for (std::size_t k = 0; k < cols.size(); ++k) w.term(coefs[k], cname[cols[k]]);
    if (w.empty()) w.term(0.0, cname[0]);  // empty row: keep it (it may be infeasible)
    out += ' ';
    out += sense;
    out += ' ';
    out += num(rhs);
    out += '\n';
  };
  for (Row r = 0; r < num_rows(); ++r) {
    const std::string base = sanitize(row_name(r));
    const std::string fallback = default_name('r', r);
    const double lo = row_lower_[r], hi = row_upper_[r];
    if (n == 0 || (lo == -kInf && hi == kInf)) {
      out += "\\ row " + unique_rows.take(base, fallback) + " omitted (" +
             (n == 0 ? "no columns" : "free row") + ")\n";
    } else if (lo == hi) {
      write_row(unique_rows.take(base, fallback), r, "=", lo);
    } else if (hi == kInf) {
      write_row(unique_rows.take(base, fallback), r, ">=", lo);
    } else if (lo == -kInf) {
      write_row(unique_rows.take(base, fallback), r, "<=", hi);
    } else {
      // CPLEX LP has no portable one-line range row.
      const std::string stem = base.empty() ? fallback : base;
      write_row(unique_rows.take(stem + "_lo", fallback + "_lo"), r, ">=", lo);
      write_row(unique_rows.take(stem + "_hi", fallback + "_hi"), r, "<=", hi);
    }
  }

  out += "Bounds\n";
  std::vector<Col> general, binary;
  for (Col c = 0; c < n; ++c) {
    const double lo = col_lower_[c], hi = col_upper_[c];
    if (col_type_[c] == VarType::Binary && lo == 0.0 && hi == 1.0) {
      binary.push_back(c);  // the Binary section implies [0, 1]
      continue;
    }
    if (col_type_[c] != VarType::Continuous) general.push_back(c);
    const std::string& x = cname[c];
    if (lo == 0.0 && hi == kInf) continue;  // the LP default
    // Appended piece by piece (see default_name about GCC 12's -Wrestrict).
    if (lo == -kInf && hi == kInf) {
      out += ' ';
      out += x;
      out += " free\n";
    } else if (lo == hi) {
      out += ' ';
      out += x;
      out += " = ";
      out += num(lo);
      out += '\n';
    } else {
      out += ' ';
      out += num(lo);
      out += " <= ";
      out += x;
      out += " <= ";
      out += num(hi);
      out += '\n';
    }
  }
  auto list = [&](const char* head, const std::vector<Col>& cols) {
    if (cols.empty()) return;
    out += head;
    std::size_t len = 0;
    for (Col c : cols) {
      out += ' ';
      out += cname[c];
      len += cname[c].size() + 1;
      if (len > 200) {
        out += '\n';
        len = 0;
      }
    }
    if (len != 0) out += '\n';
  };
  list("General\n", general);
  list("Binary\n", binary);
  out += "End\n";
  return out;
}

std::string Model::write_lp(const std::filesystem::path& path) const {
  const std::string text = to_lp_string();
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return path.string() + ": cannot open for writing: " + std::strerror(errno);
  const std::size_t written = std::fwrite(text.data(), 1, text.size(), f);
  const int write_errno = errno;
  const bool write_ok = written == text.size() && std::fflush(f) == 0;
  const int flush_errno = errno;
  const bool close_ok = std::fclose(f) == 0;
  if (!write_ok)
    return path.string() + ": write failed: " + std::strerror(written == text.size() ? flush_errno : write_errno);
  if (!close_ok) return path.string() + ": close failed: " + std::strerror(errno);
  return {};
}

}  // namespace quadlod::ilp

namespace quadlod::ilp {

ReducedModel without_fixed_columns(const Model& model, double tolerance) {
  ReducedModel r;
  const Col n = model.num_cols();
  std::vector<Col> new_index(n, ~Col{0});
  double offset = model.objective_offset();
  for (Col c = 0; c < n; ++c) {
    if (model.col_lower(c) == model.col_upper(c)) {
      offset += model.objective(c) * model.col_lower(c);
      continue;
    }
    new_index[c] = static_cast<Col>(r.kept.size());
    r.kept.push_back(c);
    r.model.add_var(model.col_type(c), model.col_lower(c), model.col_upper(c), model.objective(c));
  }
  r.model.set_objective_offset(offset);
  std::vector<Term> terms;
  for (Row row = 0; row < model.num_rows(); ++row) {
    terms.clear();
    double constant = 0.0;
    const auto cols = model.row_cols(row);
    const auto coefs = model.row_coefs(row);
    for (std::size_t k = 0; k < cols.size(); ++k) {
      if (new_index[cols[k]] == ~Col{0}) constant += coefs[k] * model.col_lower(cols[k]);
      else terms.push_back({new_index[cols[k]], coefs[k]});
    }
    const double lo = model.row_lower(row), hi = model.row_upper(row);
    if (terms.empty()) {
      if (constant < lo - tolerance || constant > hi + tolerance) ++r.violated_constant_rows;
      continue;
    }
    r.model.add_range(lo == -kInf ? -kInf : lo - constant, terms, hi == kInf ? kInf : hi - constant);
  }
  if (model.has_initial_solution()) {
    std::vector<double> start(r.kept.size());
    for (std::size_t k = 0; k < r.kept.size(); ++k) start[k] = model.initial_solution()[r.kept[k]];
    r.model.set_initial_solution(std::move(start));
  }
  return r;
}

std::vector<double> ReducedModel::expand(const Model& original, const std::vector<double>& reduced) const {
  std::vector<double> x(original.num_cols());
  for (Col c = 0; c < original.num_cols(); ++c) x[c] = original.col_lower(c);
  for (std::size_t k = 0; k < kept.size() && k < reduced.size(); ++k) x[kept[k]] = reduced[k];
  return x;
}

}  // namespace quadlod::ilp
