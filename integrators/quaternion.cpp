// Unit-quaternion rigid body as animation code integrates it (Baraff, SIGGRAPH 2001 course notes
// "Physically Based Modeling: Rigid Body Simulation" §4.4–4.6): explicit Euler or RK4 on
// q̇ = ½ q ⊗ (0, Ω), Π̇ = Π × Ω, Ω = J⁻¹Π (body frame), then q ← q/|q|. Not Lie–Poisson.
#include <Eigen/Geometry>

#include "integrators/fixed_step_loop.hpp"
#include "integrators/integrator.hpp"
#include "problems/structures/free_rigid_body.hpp"

namespace geomint {
namespace {

// The state of the body as this method sees it: the attitude quaternion (w, x, y, z) and Π.
struct QuaternionBody {
  Eigen::Vector4d quaternion;
  Eigen::Vector3d pi;
};

class QuaternionIntegrator final : public ExplicitStepper<QuaternionIntegrator> {
 public:
  QuaternionIntegrator(bool runge_kutta, bool renormalize)
      : runge_kutta_(runge_kutta), renormalize_(renormalize) {}

  MethodInfo info() const override {
    return {"quaternion", runge_kutta_ ? 4 : 1, kExplicit | kConstrained | kFreeRigidBodyOnly,
            "unit quaternion q' = q (0, Omega)/2 with Euler's equations by explicit Euler or "
            "RK4, then q/|q|: Baraff, SIGGRAPH 2001 course notes"};
  }
  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none(
        "free rigid bodies only: no harmonic oscillator to predict a limit on");
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    carried_ = false;
  }

  // As lie_poisson does, the method carries its own (q, Π) while the state is the one it wrote:
  // without renormalisation the written Q = R(q) is not orthogonal, and reading the quaternion
  // back from it (or Π through it) would hide the drift this method exists to show.
  void advance_by(const Problem& problem, State& state, double h) {
    // applicable() admits only problems that offer the structure.
    const FreeRigidBodyStructure& structure = *problem.as<FreeRigidBodyStructure>();
    const Eigen::Vector3d moments = structure.principal_moments();
    if (!carried_ || !same(state.q, written_q_) || !same(state.p, written_p_)) {
      Eigen::Matrix3d attitude;
      structure.read_body(state.q, state.p, attitude, body_.pi);
      const Eigen::Quaterniond from_matrix(attitude);
      body_.quaternion << from_matrix.w(), from_matrix.x(), from_matrix.y(), from_matrix.z();
    }
    if (runge_kutta_) {
      const QuaternionBody k1 = rate(moments, body_);
      const QuaternionBody k2 = rate(moments, shifted(body_, k1, h / 2));
      const QuaternionBody k3 = rate(moments, shifted(body_, k2, h / 2));
      const QuaternionBody k4 = rate(moments, shifted(body_, k3, h));
      body_.quaternion +=
          h / 6 * (k1.quaternion + 2 * k2.quaternion + 2 * k3.quaternion + k4.quaternion);
      body_.pi += h / 6 * (k1.pi + 2 * k2.pi + 2 * k3.pi + k4.pi);
    } else {
      body_ = shifted(body_, rate(moments, body_), h);
    }
    if (renormalize_) body_.quaternion.normalize();
    structure.write_body(rotation(body_.quaternion), body_.pi, state.q, state.p);
    written_q_ = state.q;
    written_p_ = state.p;
    carried_ = true;
    state.t += h;
    ++counters_.steps;
  }

 private:
  // (q̇, Π̇) = (½ q ⊗ (0, Ω), Π × Ω) with Ω = J⁻¹Π.
  static QuaternionBody rate(const Eigen::Vector3d& moments, const QuaternionBody& body) {
    const Eigen::Vector3d omega = body.pi.cwiseQuotient(moments);
    const double w = body.quaternion[0];
    const Eigen::Vector3d v = body.quaternion.tail<3>();
    QuaternionBody rate;
    rate.quaternion[0] = -0.5 * v.dot(omega);
    rate.quaternion.tail<3>() = 0.5 * (w * omega + v.cross(omega));
    rate.pi = body.pi.cross(omega);
    return rate;
  }

  static QuaternionBody shifted(const QuaternionBody& body, const QuaternionBody& rate,
                                double tau) {
    return {body.quaternion + tau * rate.quaternion, body.pi + tau * rate.pi};
  }

  // The rotation matrix in the form that assumes |q| = 1 (Eigen's toRotationMatrix, Shoemake
  // 1985): for |q| ≠ 1 it is not orthogonal, QᵀQ − I = O(|q|² − 1), which orthogonality_err_max
  // then shows.
  static Eigen::Matrix3d rotation(const Eigen::Vector4d& q) {
    return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
  }

  static bool same(const Vec& a, const Vec& b) {
    return a.size() == b.size() && (a.array() == b.array()).all();
  }

  bool runge_kutta_;
  bool renormalize_;
  // (q, Π) after the last step and the state written from them (advance_by).
  QuaternionBody body_;
  Vec written_q_, written_p_;
  bool carried_ = false;
};

}  // namespace

std::unique_ptr<Integrator> make_quaternion(Params& params) {
  const std::string base = params.choice(
      "base", "rk4", {"rk4", "euler"},
      "rk4 (classical Runge-Kutta, order 4) or euler (explicit Euler, order 1) on (q, Pi)");
  const bool renormalize =
      params.flag("renormalize", true, "q <- q/|q| after every step (false: the drift shows)");
  return std::make_unique<QuaternionIntegrator>(base == "rk4", renormalize);
}

}  // namespace geomint
