// Reference solutions (see reference.hpp): Gauss–Legendre s = 3 (GNI Table II.1.2; the tableau
// of integrators/high_order_coefficients.hpp, checked there in long double) in long double.
#include "harness/reference.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "harness/scene.hpp"
#include "harness/table.hpp"
#include "integrators/high_order_coefficients.hpp"

namespace geomint {
namespace {

using Real = long double;
using VecL = Eigen::Matrix<Real, Eigen::Dynamic, 1>;

constexpr int kStages = 3;
static_assert(coefficients::kGauss3.stages == kStages);
constexpr int kMaxStageIterations = 100;

// The first-order field f(t, y) with y = (q, p) in long double. q' = M⁻¹p is formed in long
// double; p' = −∇V(q) + F comes from the problem in double (problems offer only double), so each
// force evaluation carries a relative rounding error of ~1e-16. The time stepping, the stage
// iteration and the accumulation of the state are long double.
class Field {
 public:
  explicit Field(const Problem& problem) : problem_(problem), dof_(problem.dof()) {
    inverse_mass_ = problem.inverse_mass().cast<Real>();
  }
  void operator()(Real t, const VecL& y, VecL& ydot) {
    y_double_ = y.cast<double>();
    problem_.first_order_rhs(static_cast<double>(t), y_double_, ydot_double_);
    ydot.resize(2 * dof_);
    ydot.head(dof_) = inverse_mass_.cwiseProduct(y.tail(dof_));
    ydot.tail(dof_) = ydot_double_.tail(dof_).cast<Real>();
    ++evaluations;
  }
  long evaluations = 0;

 private:
  const Problem& problem_;
  int dof_;
  VecL inverse_mass_;
  Vec y_double_, ydot_double_;
};

// Fixed-step Gauss s = 3 with fixed-point stage iteration (the reference problems are not stiff
// at the reference step) and a Kahan-compensated state update.
class GaussIntegrator {
 public:
  explicit GaussIntegrator(const Problem& problem) : field_(problem), n_(2 * problem.dof()) {
    for (auto& z : z_) z = VecL::Zero(n_);
    for (auto& f : f_) f = VecL::Zero(n_);
    compensation_ = VecL::Zero(n_);
  }

  // Advances (t, y) by h; throws InputError if the stage iteration does not converge.
  void step(Real t, VecL& y, Real h) {
    // The iteration starts from the previous step's stage increments Z_i = Y_i − y (zero at the
    // first step): a smooth solution changes little from one step to the next.
    Real previous_change = std::numeric_limits<Real>::infinity();
    bool converged = false;
    for (int iteration = 0; iteration < kMaxStageIterations && !converged; ++iteration) {
      for (int i = 0; i < kStages; ++i) {
        stage_ = y + z_[i];
        field_(t + table_.c[i] * h, stage_, f_[i]);
      }
      Real change = 0, scale = 0;
      for (int i = 0; i < kStages; ++i) {
        next_z_ = VecL::Zero(n_);
        for (int j = 0; j < kStages; ++j) next_z_ += (h * table_.a[i][j]) * f_[j];
        change = std::max(change, (next_z_ - z_[i]).template lpNorm<Eigen::Infinity>());
        scale = std::max(scale, next_z_.template lpNorm<Eigen::Infinity>());
        z_[i] = next_z_;
      }
      // Converged when the increments stop changing, or stagnate at the round-off floor of the
      // double force evaluations (~1e-16 of the increment).
      converged = change <= 1e-18L * scale ||
                  (iteration >= 2 && change >= previous_change && change <= 1e-12L * scale);
      previous_change = change;
    }
    if (!converged) {
      throw InputError(
          fmt::format("reference: Gauss stage iteration did not converge at t={} with dt={}; "
                      "pass a smaller --dt",
                      static_cast<double>(t), static_cast<double>(h)));
    }
    // The slopes f_ are those of the last iterate but one; they differ from the slopes at z_ by
    // L·change, at the round-off floor once converged.
    increment_ = VecL::Zero(n_);
    for (int i = 0; i < kStages; ++i) increment_ += (h * table_.b[i]) * f_[i];
    // Kahan summation: y += increment, carrying the low-order bits lost in the addition.
    for (int k = 0; k < n_; ++k) {
      const Real corrected = increment_[k] - compensation_[k];
      const Real sum = y[k] + corrected;
      compensation_[k] = (sum - y[k]) - corrected;
      y[k] = sum;
    }
  }
  long evaluations() const { return field_.evaluations; }

 private:
  Field field_;
  const coefficients::PartitionedTableau& table_ = coefficients::kGauss3;  // â = a for Gauss
  int n_;
  VecL z_[kStages], f_[kStages], next_z_, stage_, increment_, compensation_;
};

// One run from the initial state; returns y at each output time (steps_per_output steps apart).
std::vector<VecL> run_gauss(const Problem& problem, Real output_every, long outputs,
                            long steps_per_output, long& steps) {
  const State initial = problem.initial_state();
  const int dof = problem.dof();
  VecL y(2 * dof);
  y.head(dof) = initial.q.cast<Real>();
  y.tail(dof) = initial.p.cast<Real>();
  const Real t0 = initial.t;
  const Real h = output_every / static_cast<Real>(steps_per_output);
  GaussIntegrator gauss(problem);
  std::vector<VecL> out;
  steps = 0;
  for (long k = 1; k <= outputs; ++k) {
    for (long s = 0; s < steps_per_output; ++s) {
      const Real t = t0 + static_cast<Real>((k - 1) * steps_per_output + s) * h;
      gauss.step(t, y, h);
      ++steps;
    }
    if (!y.allFinite()) {
      throw InputError(fmt::format("reference: non-finite state at t={}; pass a smaller --dt",
                                   static_cast<double>(t0 + k * output_every)));
    }
    out.push_back(y);
  }
  return out;
}

std::string number17(double value) { return fmt::format("{:.17g}", value); }

// Error against a reference row (see make_reference_observer).
class ReferenceErrorObserver : public Observer {
 public:
  explicit ReferenceErrorObserver(std::shared_ptr<const ReferenceSolution> reference)
      : reference_(std::move(reference)) {}
  void begin(const Problem&, const State& state, double t_end) override {
    t_last_ = state.t + t_end;
  }
  void observe(const Problem&, const State& state) override {
    const int row = reference_->row_at(state.t);
    if (row < 0) return;
    const double error = std::sqrt((state.q - reference_->q[row]).squaredNorm() +
                                   (state.p - reference_->p[row]).squaredNorm());
    error_max_ = std::max(error_max_, error);
    if (reference_->row_at(t_last_) == row) {
      error_final_ = error;
      reached_end_ = true;
    }
  }
  void finish(std::map<std::string, double>& metrics) const override {
    if (!reached_end_) return;
    metrics["error_max"] = error_max_;
    metrics["error_final"] = error_final_;
  }

 private:
  std::shared_ptr<const ReferenceSolution> reference_;
  double t_last_ = 0, error_max_ = 0, error_final_ = 0;
  bool reached_end_ = false;
};

}  // namespace

std::string reference_path(const std::string& dir, const std::string& problem_spec) {
  const auto problem = make_problem(problem_spec);
  return (std::filesystem::path(dir) / (sanitize_for_path(problem->spec()) + ".csv")).string();
}

ReferenceSummary generate_reference(const ReferenceOptions& options) {
  const auto problem = make_problem(options.problem_spec);
  if (!(options.t_end > 0 && std::isfinite(options.t_end))) {
    throw InputError(fmt::format("--t-end must be a finite number > 0 (got {})", options.t_end));
  }
  const double dt_wanted = options.dt > 0 ? options.dt : problem->default_dt() / 8;
  if (!(dt_wanted > 0 && std::isfinite(dt_wanted)) || options.dt < 0) {
    throw InputError(fmt::format("--dt must be a finite number > 0 (got {})", options.dt));
  }
  const double every = options.output_every > 0 ? options.output_every : options.t_end / 100;
  const double ratio = options.t_end / every;
  const long outputs = std::lround(ratio);
  if (!(options.output_every >= 0) || !(ratio <= kMaxReferenceRows) || outputs < 1 ||
      std::abs(ratio - static_cast<double>(outputs)) > 1e-9 * ratio) {
    throw InputError(
        fmt::format("--every must divide --t-end into a whole number of outputs, at most {:g} "
                    "(got --every {} for --t-end {})",
                    kMaxReferenceRows, every, options.t_end));
  }
  // An even number of steps per output, so the check run at 2·dt lands on the same times.
  long steps_per_output = static_cast<long>(std::ceil(every / dt_wanted - 1e-9));
  steps_per_output += steps_per_output % 2;
  if (static_cast<double>(steps_per_output) * static_cast<double>(outputs) > 1e10) {
    throw InputError(fmt::format("--t-end/--dt = {:g} steps is more than the allowed 1e10",
                                 static_cast<double>(steps_per_output) * outputs));
  }

  ReferenceSummary summary;
  summary.path = options.out_path.empty() ? reference_path(kReferenceDir, options.problem_spec)
                                          : options.out_path;
  check_output_file(summary.path, options.out_path.empty() ? "reference file" : "--out");
  const auto start = std::chrono::steady_clock::now();
  long check_steps = 0;
  const std::vector<VecL> fine =
      run_gauss(*problem, every, outputs, steps_per_output, summary.steps);
  const std::vector<VecL> check =
      run_gauss(*problem, every, outputs, steps_per_output / 2, check_steps);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.dt = every / static_cast<double>(steps_per_output);
  for (long k = 0; k < outputs; ++k) {
    const double difference = static_cast<double>((fine[k] - check[k]).norm());
    summary.estimated_error_max = std::max(summary.estimated_error_max, difference);
    if (k == outputs - 1) summary.estimated_error_final = difference;
  }

  const int dof = problem->dof();
  std::vector<std::string> columns = {"t"};
  for (int i = 0; i < dof; ++i) columns.push_back(fmt::format("q_{}", i));
  for (int i = 0; i < dof; ++i) columns.push_back(fmt::format("p_{}", i));
  std::vector<Row> rows;
  const State initial = problem->initial_state();
  auto add_row = [&](double t, const VecL& y) {
    Row row;
    row["t"] = number17(t);
    for (int i = 0; i < 2 * dof; ++i) row[columns[1 + i]] = number17(static_cast<double>(y[i]));
    rows.push_back(std::move(row));
  };
  VecL y0(2 * dof);
  y0.head(dof) = initial.q.cast<Real>();
  y0.tail(dof) = initial.p.cast<Real>();
  add_row(initial.t, y0);
  for (long k = 0; k < outputs; ++k) {
    const double t = k == outputs - 1 ? initial.t + options.t_end
                                      : initial.t + static_cast<double>(k + 1) * every;
    add_row(t, fine[k]);
  }

  auto lines = provenance(options.command_line);
  lines.emplace_back("reference_problem", problem->spec());
  lines.emplace_back("reference_method",
                     "Gauss-Legendre collocation s=3 (order 6), long double state, "
                     "Kahan-compensated update, fixed-point stage iteration; forces in double");
  lines.emplace_back("reference_dt", number17(summary.dt));
  lines.emplace_back("reference_check_dt", number17(2 * summary.dt));
  lines.emplace_back("reference_steps", std::to_string(summary.steps));
  lines.emplace_back("estimated_error_final", fmt::format("{:.3g}", summary.estimated_error_final));
  lines.emplace_back("estimated_error_max", fmt::format("{:.3g}", summary.estimated_error_max));
  lines.emplace_back("estimated_error_definition",
                     "2-norm of (q, p) between the run at dt and the check run at 2*dt (an upper "
                     "estimate: the order-6 error at dt is ~1/64 of it), max over the rows");
  write_file_atomic(summary.path, to_csv(rows, columns, lines));
  return summary;
}

int ReferenceSolution::row_at(double t) const {
  const double tolerance = 1e-9 * std::max(1.0, std::abs(t));
  auto it = std::lower_bound(times.begin(), times.end(), t - tolerance);
  if (it == times.end() || std::abs(*it - t) > tolerance) return -1;
  return static_cast<int>(it - times.begin());
}

std::shared_ptr<const ReferenceSolution> load_reference(const std::string& path,
                                                        const Problem& problem) {
  std::ifstream file(path);
  if (!file) throw InputError(fmt::format("reference file '{}' cannot be read", path));
  std::stringstream buffer;
  buffer << file.rdbuf();
  const std::string text = buffer.str();
  auto fail = [&path](const std::string& what) {
    return InputError(fmt::format(
        "reference file '{}' is not a valid reference ({}); regenerate it with `geomint "
        "reference`",
        path, what));
  };

  auto solution = std::make_shared<ReferenceSolution>();
  solution->path = path;
  bool has_error = false;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("# ", 0) != 0) continue;
    const auto colon = line.find(": ");
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(2, colon - 2), value = line.substr(colon + 2);
    if (key == "reference_problem") solution->problem_spec = value;
    if (key == "estimated_error_max") {
      char* end = nullptr;
      solution->estimated_error = std::strtod(value.c_str(), &end);
      has_error = end != value.c_str() && *end == '\0';
    }
  }
  if (solution->problem_spec.empty()) throw fail("no '# reference_problem:' line");
  if (solution->problem_spec != problem.spec()) {
    throw fail(
        fmt::format("it is for problem '{}', not '{}'", solution->problem_spec, problem.spec()));
  }
  if (!has_error) throw fail("no numeric '# estimated_error_max:' line");

  std::vector<Row> rows;
  try {
    rows = parse_csv(text);
  } catch (const std::exception& error) {
    throw fail(error.what());
  }
  if (rows.empty()) throw fail("no rows");
  const int dof = problem.dof();
  for (size_t r = 0; r < rows.size(); ++r) {
    auto value = [&](const std::string& column) {
      const auto it = rows[r].find(column);
      if (it == rows[r].end()) throw fail(fmt::format("row {} has no column '{}'", r + 1, column));
      char* end = nullptr;
      const double v = std::strtod(it->second.c_str(), &end);
      if (end == it->second.c_str() || *end != '\0' || !std::isfinite(v)) {
        throw fail(fmt::format("row {} column '{}' is not a finite number: '{}'", r + 1, column,
                               it->second));
      }
      return v;
    };
    if (rows[r].size() != static_cast<size_t>(1 + 2 * dof)) {
      throw fail(fmt::format("row {} has {} columns, expected t, q_0..q_{}, p_0..p_{}", r + 1,
                             rows[r].size(), dof - 1, dof - 1));
    }
    const double t = value("t");
    if (!solution->times.empty() && !(t > solution->times.back())) {
      throw fail(fmt::format("times are not increasing at row {}", r + 1));
    }
    Vec q(dof), p(dof);
    for (int i = 0; i < dof; ++i) {
      q[i] = value(fmt::format("q_{}", i));
      p[i] = value(fmt::format("p_{}", i));
    }
    solution->times.push_back(t);
    solution->q.push_back(std::move(q));
    solution->p.push_back(std::move(p));
  }
  return solution;
}

std::unique_ptr<Observer> make_reference_observer(
    std::shared_ptr<const ReferenceSolution> reference) {
  return std::make_unique<ReferenceErrorObserver>(std::move(reference));
}

}  // namespace geomint
