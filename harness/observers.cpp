// Metric observers (DESIGN.md §3): energy error and drift, momentum maps, error against the
// exact solution.
#include "harness/observers.hpp"

#include <cmath>
#include <limits>

namespace geomint {
namespace {

constexpr int kDriftWindows = 20;

double energy_reference(const Problem& problem, double energy0, double t) {
  if (!problem.has(kForce)) return energy0;
  const State exact = problem.exact(t);
  return problem.energy(exact.q, exact.p);
}

// energy_err_max, energy_err_final: |H(q_k, p_k) − H_ref(t_k)| / |H_0|; energy_drift: slope
// per unit time of the per-window maxima of that error over kDriftWindows equal time windows.
class EnergyObserver : public Observer {
 public:
  void begin(const Problem& problem, const State& state, double t_end) override {
    energy0_ = problem.energy(state.q, state.p);
    scale_ = std::abs(energy0_) > 0 ? std::abs(energy0_) : 1.0;
    t0_ = state.t;
    window_length_ = (t_end - state.t) / kDriftWindows;
    window_max_.assign(kDriftWindows, -1.0);
  }
  void observe(const Problem& problem, const State& state) override {
    const double error =
        std::abs(problem.energy(state.q, state.p) - energy_reference(problem, energy0_, state.t)) /
        scale_;
    err_max_ = std::max(err_max_, error);
    err_final_ = error;
    int window = static_cast<int>((state.t - t0_) / window_length_);
    window = std::clamp(window, 0, kDriftWindows - 1);
    window_max_[window] = std::max(window_max_[window], error);
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics["energy_err_max"] = err_max_;
    metrics["energy_err_final"] = err_final_;
    std::vector<double> times, maxima;
    for (int w = 0; w < kDriftWindows; ++w) {
      if (window_max_[w] < 0) continue;
      times.push_back(t0_ + (w + 0.5) * window_length_);
      maxima.push_back(window_max_[w]);
    }
    metrics["energy_drift"] = window_maxima_slope(times, maxima);
  }

 private:
  double energy0_ = 0, scale_ = 1, t0_ = 0, window_length_ = 1;
  double err_max_ = 0, err_final_ = 0;
  std::vector<double> window_max_;
};

// Absolute error ‖J(q_k, p_k) − J(q_0, p_0)‖ of a momentum map J.
class MomentumObserver : public Observer {
 public:
  using Map = Vec (Problem::*)(const Vec&, const Vec&) const;
  MomentumObserver(Map map, std::string column) : map_(map), column_(std::move(column)) {}
  void begin(const Problem& problem, const State& state, double) override {
    initial_ = (problem.*map_)(state.q, state.p);
  }
  void observe(const Problem& problem, const State& state) override {
    err_max_ = std::max(err_max_, ((problem.*map_)(state.q, state.p) - initial_).norm());
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics[column_] = err_max_;
  }

 private:
  Map map_;
  std::string column_;
  Vec initial_;
  double err_max_ = 0;
};

// error_max, error_final: ‖(q_k − q(t_k), p_k − p(t_k))‖₂ against the exact solution.
class ExactErrorObserver : public Observer {
 public:
  void begin(const Problem&, const State&, double) override {}
  void observe(const Problem& problem, const State& state) override {
    const State exact = problem.exact(state.t);
    const double error =
        std::sqrt((state.q - exact.q).squaredNorm() + (state.p - exact.p).squaredNorm());
    error_max_ = std::max(error_max_, error);
    error_final_ = error;
  }
  void finish(std::map<std::string, double>& metrics) const override {
    metrics["error_max"] = error_max_;
    metrics["error_final"] = error_final_;
  }

 private:
  double error_max_ = 0, error_final_ = 0;
};

}  // namespace

bool has_energy_reference(const Problem& problem) {
  return !problem.has(kForce) || problem.has(kExact);
}

std::vector<std::unique_ptr<Observer>> make_metric_observers(const Problem& problem) {
  std::vector<std::unique_ptr<Observer>> observers;
  if (has_energy_reference(problem)) observers.push_back(std::make_unique<EnergyObserver>());
  if (problem.has(kLinearMomentum)) {
    observers.push_back(
        std::make_unique<MomentumObserver>(&Problem::linear_momentum, "momentum_err_max"));
  }
  if (problem.has(kAngularMomentum)) {
    observers.push_back(
        std::make_unique<MomentumObserver>(&Problem::angular_momentum, "angular_momentum_err_max"));
  }
  if (problem.has(kExact)) observers.push_back(std::make_unique<ExactErrorObserver>());
  return observers;
}

double window_maxima_slope(const std::vector<double>& window_time,
                           const std::vector<double>& window_max) {
  const size_t n = window_time.size();
  if (n < 2) return 0.0;
  double mean_t = 0, mean_e = 0;
  for (size_t i = 0; i < n; ++i) {
    mean_t += window_time[i] / n;
    mean_e += window_max[i] / n;
  }
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < n; ++i) {
    sxy += (window_time[i] - mean_t) * (window_max[i] - mean_e);
    sxx += (window_time[i] - mean_t) * (window_time[i] - mean_t);
  }
  return sxx > 0 ? sxy / sxx : 0.0;
}

}  // namespace geomint
