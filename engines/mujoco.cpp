// The `mujoco` method: MuJoCo's own mj_step on the planar chain a problem is
// (engines/planar_chain.hpp), its state read back as the problem's (θ, p = M(θ)θ̇).
#include "engines/mujoco.hpp"

#include <fmt/format.h>
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <array>
#include <cstring>
#include <mutex>

#include "engines/engine_method.hpp"

namespace geomint::engines {
namespace {

// MuJoCo reports warnings through one global hook and a counter per kind in mjData; the hook
// keeps the text of the last one (per thread: sweeps step several models at once), which the
// step turns into its status message.
thread_local std::string last_mujoco_warning;
void record_mujoco_warning(const char* message) { last_mujoco_warning = message; }

const char* warning_name(int warning) {
  static const std::array<const char*, mjNWARNING> names = {
      "mjWARN_INERTIA", "mjWARN_CONTACTFULL", "mjWARN_CNSTRFULL", "mjWARN_VGEOMFULL",
      "mjWARN_BADQPOS", "mjWARN_BADQVEL",     "mjWARN_BADQACC",   "mjWARN_BADCTRL"};
  return names[warning];
}

// MuJoCo refuses a moving body whose inertia components are not all above mjMINVAL (1e-15), so a
// point mass m at the end of a rod of length l gets the rotational inertia 1e-14·m·l² (at least
// 10·mjMINVAL): a relative change of 1e-14 in its share of the mass matrix, far below the
// fidelity tests' 1e-9 and at round-off in the identification tests (docs/ENGINES.md).
double point_mass_inertia(double mass, double length) {
  return std::max(10 * mjMINVAL, 1e-14 * mass * length * length);
}

// The <mujoco>, <compiler> and <option> lines of a model: the integrator, gravity along −z and the
// flags. Clean: no contact or constraint machinery, no passive forces (the joints carry neither
// damping, stiffness nor armature, written out per joint), energies computed for the tests.
std::string model_header(const std::string& name, double gravity, const MujocoOptions& options) {
  const std::string integrator = options.integrator == "rk4"        ? "RK4"
                                 : options.integrator == "implicit" ? "implicit"
                                                                    : "Euler";
  const std::string flags = options.shipped_defaults
                                ? R"(<flag energy="enable"/>)"
                                : R"(<flag contact="disable" constraint="disable" )"
                                  R"(passive="disable" energy="enable"/>)";
  return fmt::format(
      "<mujoco model=\"{}\">\n"
      "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
      "  <option timestep=\"0.01\" integrator=\"{}\" gravity=\"0 0 {:.17g}\">{}</option>\n"
      "  <worldbody>\n",
      name, integrator, -gravity, flags);
}

std::string joint_extras(const MujocoOptions& options) {
  return options.shipped_defaults ? ""
                                  : R"( damping="0" stiffness="0" armature="0" frictionloss="0")";
}

std::string chain_xml(const PlanarChain& chain, const MujocoOptions& options) {
  std::string xml = model_header("geomint_chain", chain.gravity, options);
  // Rod i hangs along −z from its joint; the axis −y makes a positive angle swing the rod
  // towards +x, the problems' convention x = Σ lᵢ sin θᵢ.
  std::string closing;
  for (int i = 0; i < chain.links(); ++i) {
    const double l = chain.length[i];
    const double inertia = point_mass_inertia(chain.mass[i], l);
    const double offset = i == 0 ? 0.0 : chain.length[i - 1];
    xml += fmt::format(
        "<body pos=\"0 0 {:.17g}\"><joint type=\"hinge\" axis=\"0 -1 0\"{}/>"
        "<inertial pos=\"0 0 {:.17g}\" mass=\"{:.17g}\" diaginertia=\"{:.17g} {:.17g} "
        "{:.17g}\"/>\n",
        -offset, joint_extras(options), -l, chain.mass[i], inertia, inertia, inertia);
    closing += "</body>";
  }
  xml += closing + "\n  </worldbody>\n</mujoco>\n";
  return xml;
}

// The same chain as URDF (links and joints side by side, no nesting): what MJCF's header and joint
// attributes say is set on the compiled model instead (apply_chain_options). Continuous joints
// have no limits; clean joints get zero damping and friction, as the MJCF ones do.
std::string chain_urdf(const PlanarChain& chain, const MujocoOptions& options) {
  std::string urdf =
      "<robot name=\"geomint_chain\">\n"
      "  <mujoco><compiler fusestatic=\"false\" balanceinertia=\"false\"/></mujoco>\n"
      "  <link name=\"pivot\"/>\n";
  const std::string dynamics =
      options.shipped_defaults ? "" : R"(<dynamics damping="0" friction="0"/>)";
  for (int i = 0; i < chain.links(); ++i) {
    const double l = chain.length[i];
    const double inertia = point_mass_inertia(chain.mass[i], l);
    const double offset = i == 0 ? 0.0 : chain.length[i - 1];
    const std::string parent = i == 0 ? "pivot" : fmt::format("link{}", i - 1);
    urdf += fmt::format(
        "  <link name=\"link{0}\"><inertial><origin xyz=\"0 0 {1:.17g}\"/><mass "
        "value=\"{2:.17g}\"/><inertia ixx=\"{3:.17g}\" iyy=\"{3:.17g}\" izz=\"{3:.17g}\" "
        "ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n"
        "  <joint name=\"joint{0}\" type=\"continuous\"><parent link=\"{4}\"/><child "
        "link=\"link{0}\"/><origin xyz=\"0 0 {5:.17g}\"/><axis xyz=\"0 -1 0\"/>{6}</joint>\n",
        i, -l, chain.mass[i], inertia, parent, -offset, dynamics);
  }
  return urdf + "</robot>\n";
}

// What model_header writes into an MJCF model, on a model compiled from URDF: the integrator,
// gravity along −z, energies on and, clean, contact, constraints and passive forces off.
void apply_chain_options(mjModel* model, double gravity, const MujocoOptions& options) {
  model->opt.integrator = options.integrator == "rk4"        ? mjINT_RK4
                          : options.integrator == "implicit" ? mjINT_IMPLICIT
                                                             : mjINT_EULER;
  model->opt.gravity[0] = 0;
  model->opt.gravity[1] = 0;
  model->opt.gravity[2] = -gravity;
  model->opt.enableflags |= mjENBL_ENERGY;
  if (!options.shipped_defaults) {
    model->opt.disableflags |= mjDSBL_CONTACT | mjDSBL_CONSTRAINT | mjDSBL_PASSIVE;
  }
}

// One body at the origin on a ball joint (a free joint for the free body), its centre of mass at
// the principal centre, the principal moments on the body's own axes.
std::string rotor_xml(const Rotor& rotor, const MujocoOptions& options) {
  const Eigen::Vector3d& c = rotor.principal_centre;
  const Eigen::Vector3d& I = rotor.principal_moments;
  return model_header("geomint_rotor", rotor.gravity, options) +
         fmt::format(
             "<body pos=\"0 0 0\"><joint type=\"{}\"{}/>"
             "<inertial pos=\"{:.17g} {:.17g} {:.17g}\" mass=\"{:.17g}\" "
             "diaginertia=\"{:.17g} {:.17g} {:.17g}\"/></body>\n"
             "  </worldbody>\n</mujoco>\n",
             rotor.free() ? "free" : "ball", joint_extras(options), c[0], c[1], c[2], rotor.mass,
             I[0], I[1], I[2]);
}

// Compiles `xml` from memory (a virtual file system holding the one MJCF file); the warning hook
// is installed once (it is one global of the library, and sweeps build models on several threads).
mjModel* load_model(const std::string& xml, const std::string& what,
                    const char* file_name = "geomint_model.xml") {
  static std::once_flag hook_installed;
  std::call_once(hook_installed, [] { mju_user_warning = &record_mujoco_warning; });
  auto vfs = std::make_unique<mjVFS>();  // mjVFS is large: on the heap
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), file_name, static_cast<int>(xml.size())) != 0) {
    throw InputError("mujoco: cannot create the model file in MuJoCo's virtual file system");
  }
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), file_name)], xml.data(), xml.size());
  std::array<char, 1000> error{};
  mjModel* model = mj_loadXML(file_name, vfs.get(), error.data(), static_cast<int>(error.size()));
  mj_deleteVFS(vfs.get());
  if (model == nullptr) {
    throw InputError(fmt::format("mujoco: MuJoCo refused the model of {}: {}", what, error.data()));
  }
  return model;
}

// One mj_step of length h; a warning MuJoCo raises in it (bad qacc, qpos, qvel: its instability
// detector, which would also reset the state) is a failed status naming it.
// `split`: mj_step2 then mj_step1 instead of mj_step (Euler and implicit only, MuJoCo's documented
// equivalent, bit for bit): the step ends with the position stage at the new state, so its mass
// matrix qM is there for the copy out (MujocoChain::momentum_absolute).
StepStatus step_model(mjModel* model, mjData* data, double h, bool split = false) {
  model->opt.timestep = h;
  std::array<int, mjNWARNING> before{};
  for (int i = 0; i < mjNWARNING; ++i) before[i] = data->warning[i].number;
  if (split) {
    mj_step2(model, data);
    mj_step1(model, data);
  } else {
    mj_step(model, data);
  }
  for (int i = 0; i < mjNWARNING; ++i) {
    if (data->warning[i].number != before[i]) {
      return StepStatus::failure(
          fmt::format("mujoco_{}", warning_name(i)),
          fmt::format("MuJoCo warning {} in mj_step: {}", warning_name(i), last_mujoco_warning));
    }
  }
  return StepStatus::success();
}

}  // namespace

const std::vector<std::string>& mujoco_integrators() {
  static const std::vector<std::string> names = {"euler", "rk4", "implicit"};
  return names;
}

MujocoChain::MujocoChain(const PlanarChain& chain, const MujocoOptions& options) {
  const std::string what = fmt::format("{} links", chain.links());
  if (chain.links() <= kMaxMjcfChainLinks) {
    xml_ = chain_xml(chain, options);
    model_ = load_model(xml_, what);
  } else {
    xml_ = chain_urdf(chain, options);
    model_ = load_model(xml_, what, "geomint_model.urdf");
    apply_chain_options(model_, chain.gravity, options);
  }
  data_ = mj_makeData(model_);
  // mj_step2 integrates with Euler when the model asks for RK4: RK4 keeps mj_step.
  split_step_ = options.integrator != "rk4";
}

MujocoChain::~MujocoChain() {
  if (data_ != nullptr) mj_deleteData(data_);
  if (model_ != nullptr) mj_deleteModel(model_);
}

void MujocoChain::set_state(const Vec& theta, const Vec& theta_dot) {
  absolute_to_relative(theta, relative_);
  absolute_to_relative(theta_dot, relative_rate_);
  for (int i = 0; i < model_->nq; ++i) {
    data_->qpos[i] = relative_[i];
    data_->qvel[i] = relative_rate_[i];
  }
  // Positions, mass matrix and energies at this state (mj_step recomputes them anyway).
  mj_forward(model_, data_);
}

void MujocoChain::get_state(Vec& theta, Vec& theta_dot) const {
  const Eigen::Map<const Vec> qpos(data_->qpos, model_->nq);
  const Eigen::Map<const Vec> qvel(data_->qvel, model_->nv);
  relative_to_absolute(qpos, theta);
  relative_to_absolute(qvel, theta_dot);
}

DenseMatrix MujocoChain::mass_matrix_absolute() const {
  const int n = model_->nv;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> relative(n, n);
  mj_fullM(model_, relative.data(), data_->qM);
  // T = ½φ̇ᵀM_φφ̇ with φ̇ = Dθ̇ (D the difference matrix): M_θ = DᵀM_φD.
  DenseMatrix difference = DenseMatrix::Identity(n, n);
  for (int i = 1; i < n; ++i) difference(i, i - 1) = -1;
  return difference.transpose() * relative * difference;
}

double MujocoChain::potential() const { return data_->energy[0]; }
double MujocoChain::kinetic() const { return data_->energy[1]; }

StepStatus MujocoChain::step(double h) { return step_model(model_, data_, h, split_step_); }

bool MujocoChain::momentum_absolute(Vec& p) {
  if (!split_step_) return false;
  // p_θ = DᵀM_φDθ̇ = Dᵀ(M_φ φ̇): MuJoCo's sparse product with qvel, then (Dᵀy)ᵢ = yᵢ − yᵢ₊₁.
  const int n = model_->nv;
  relative_rate_.resize(n);
  mj_mulM(model_, data_, relative_rate_.data(), data_->qvel);
  p.resize(n);
  for (int i = 0; i < n; ++i) p[i] = relative_rate_[i] - (i + 1 < n ? relative_rate_[i + 1] : 0.0);
  return true;
}

MujocoRotor::MujocoRotor(const Rotor& rotor, const MujocoOptions& options)
    : xml_(rotor_xml(rotor, options)) {
  model_ = load_model(xml_, "a rigid body");
  data_ = mj_makeData(model_);
  // A free joint's qpos starts with the position (3), its qvel with the linear velocity (3).
  rotation_offset_ = rotor.free() ? 3 : 0;
  spin_offset_ = rotor.free() ? 3 : 0;
}

MujocoRotor::~MujocoRotor() {
  if (data_ != nullptr) mj_deleteData(data_);
  if (model_ != nullptr) mj_deleteModel(model_);
}

void MujocoRotor::set_state(const RotorState& principal) {
  mj_resetData(model_, data_);
  const Eigen::Quaterniond q(principal.attitude);
  double* quaternion = data_->qpos + rotation_offset_;  // MuJoCo's order: w, x, y, z
  quaternion[0] = q.w(), quaternion[1] = q.x(), quaternion[2] = q.y(), quaternion[3] = q.z();
  for (int k = 0; k < 3; ++k) data_->qvel[spin_offset_ + k] = principal.omega[k];
  mj_forward(model_, data_);
}

RotorState MujocoRotor::get_state() const {
  const double* quaternion = data_->qpos + rotation_offset_;
  RotorState state;
  state.attitude = Eigen::Quaterniond(quaternion[0], quaternion[1], quaternion[2], quaternion[3])
                       .toRotationMatrix();
  for (int k = 0; k < 3; ++k) state.omega[k] = data_->qvel[spin_offset_ + k];
  return state;
}

Eigen::Matrix3d MujocoRotor::rotational_mass_matrix() const {
  const int n = model_->nv;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> full(n, n);
  mj_fullM(model_, full.data(), data_->qM);
  return full.block<3, 3>(spin_offset_, spin_offset_);
}

double MujocoRotor::potential() const { return data_->energy[0]; }
double MujocoRotor::kinetic() const { return data_->energy[1]; }
StepStatus MujocoRotor::step(double h) { return step_model(model_, data_, h); }

namespace {

// MuJoCo's own step on a planar chain or a rigid body (EngineMethod writes the state into
// qpos/qvel only when the harness changed it).
class MujocoMethod final : public EngineMethod<MujocoChain, MujocoRotor, MujocoOptions> {
 public:
  explicit MujocoMethod(MujocoOptions options) : EngineMethod(std::move(options), "MuJoCo") {}

  MethodInfo info() const override {
    if (options_.integrator == "rk4") {
      return {"mujoco", 4, kExplicit | kGeneralLagrangian,
              "MuJoCo 2.2.2 mjINT_RK4 (mj_RungeKutta)"};
    }
    // euler and implicit both update the velocity first, then the position with it; implicit
    // also treats damping implicitly (there is none in these problems).
    return {"mujoco", 1,
            (options_.integrator == "implicit" ? kImplicit : kExplicit) | kGeneralLagrangian,
            options_.integrator == "implicit" ? "MuJoCo 2.2.2 mjINT_IMPLICIT (mj_implicit)"
                                              : "MuJoCo 2.2.2 mjINT_EULER (mj_Euler)"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    // Without damping MuJoCo's Euler and implicit steps are symplectic Euler (hω < 2); RK4's
    // real-axis bound is 2√2.
    return StabilityPrediction::limit(options_.integrator == "rk4" ? 2 * std::sqrt(2.0) : 2.0);
  }
};

}  // namespace

}  // namespace geomint::engines

namespace geomint {

std::unique_ptr<Integrator> make_mujoco(Params& params) {
  engines::MujocoOptions options;
  options.integrator =
      params.choice("integrator", "euler", engines::mujoco_integrators(),
                    "MuJoCo's integrator (mjtIntegrator): euler (semi-implicit), rk4, implicit "
                    "(implicit in velocity)");
  options.shipped_defaults =
      params.choice("defaults", "clean", {"clean", "shipped"},
                    "clean: everything the problem lacks switched off; shipped: MuJoCo's own "
                    "defaults") == "shipped";
  return std::make_unique<engines::MujocoMethod>(std::move(options));
}

}  // namespace geomint
