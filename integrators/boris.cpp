// The Boris pusher (Boris 1970; Qin et al., Phys. Plasmas 20, 084503 (2013)): drift ½h, the
// velocity kick v⁺ − v⁻ = (qh/m)(E + ½(v⁺ + v⁻) × B) solved exactly as half E kick, rotation, half
// E kick, drift ½h. Explicit, symmetric, volume-preserving, order 2; not symplectic.
#include <Eigen/Geometry>

#include "integrators/fixed_step_loop.hpp"
#include "integrators/integrator.hpp"
#include "problems/structures/charged_particle.hpp"

namespace geomint {
namespace {

using Vector3 = Eigen::Vector3d;

class Boris final : public ExplicitStepper<Boris> {
 public:
  MethodInfo info() const override {
    return {"boris", 2, kExplicit | kSymmetric | kChargedParticleOnly,
            "Boris, Proc. 4th Conf. Numer. Sim. Plasmas (1970); Qin et al., Phys. Plasmas 20, "
            "084503 (2013)"};
  }
  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none(
        "charged particles only: no harmonic oscillator to predict a limit on");
  }

  // The state is canonical (q = x, p = m v + qA(x)); the pusher works on (x, v), so v is read
  // through A at the step's start and p written back through A at its end.
  void advance_by(const Problem& problem, State& state, double h) {
    // applicable() admits only problems that offer the structure.
    const ChargedParticleStructure& particle = *problem.as<ChargedParticleStructure>();
    const double mass = particle.particle_mass(), charge = particle.particle_charge();
    Vector3 x = state.q.head<3>();
    Vector3 v = (Vector3(state.p.head<3>()) - charge * particle.vector_potential(x)) / mass;
    x += h / 2 * v;
    Vector3 E, B;
    particle.fields(x, E, B);
    const double kick = charge * h / (2 * mass);
    const Vector3 v_minus = v + kick * E;
    // The rotation by 2 arctan(|t|) about B that maps v⁻ to v⁺ with v⁺ − v⁻ = (v⁺ + v⁻) × t:
    // the implicit midpoint rule of v̇ = (q/m) v × B, solved in closed form (|v| kept exactly).
    const Vector3 t = kick * B;
    const Vector3 s = 2 * t / (1 + t.squaredNorm());
    const Vector3 v_prime = v_minus + v_minus.cross(t);
    const Vector3 v_plus = v_minus + v_prime.cross(s);
    v = v_plus + kick * E;
    x += h / 2 * v;
    state.q.head<3>() = x;
    state.p.head<3>() = mass * v + charge * particle.vector_potential(x);
    state.t += h;
    ++counters_.steps;
    ++counters_.force_evals;
  }
};

}  // namespace

std::unique_ptr<Integrator> make_boris(Params&) { return std::make_unique<Boris>(); }

}  // namespace geomint
