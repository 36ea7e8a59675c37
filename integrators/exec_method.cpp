// The `exec` method: a user's integrator in any language, run as a child process and driven over
// its stdin/stdout with JSON lines or binary doubles (docs/PYTHON.md "Integrators in any language:
// exec:"). Whatever the process does wrong ends the run as a failure row that names it.
#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "integrators/exec_process.hpp"
#include "integrators/integrator.hpp"
#include "integrators/tangent.hpp"
#include "problems/shell_words.hpp"

namespace geomint {
namespace {

using nlohmann::json;

constexpr const char* kHelp = "docs/PYTHON.md, \"Integrators in any language: exec:\"";

// Binary frames: [code, count, count values], all native doubles (docs/PYTHON.md).
// Plain ints (not an enum) because they are compared with the doubles of a frame.
constexpr int kReset = 1, kStep = 2, kGradient = 3, kResult = 4, kError = 5, kTangentStep = 6,
              kHessian = 7;

// The flags a process may declare: what it can honour with (t, q, p), M⁻¹ and ∇V alone.
const std::vector<std::pair<std::string, MethodFlag>>& declarable_flags() {
  static const std::vector<std::pair<std::string, MethodFlag>> flags = {
      {"explicit", kExplicit},       {"implicit", kImplicit},
      {"symplectic", kSymplectic},   {"symmetric", kSymmetric},
      {"variational", kVariational}, {"energy_preserving", kEnergyPreserving}};
  return flags;
}

std::string declarable_flag_names() {
  std::vector<std::string> names;
  for (const auto& [name, flag] : declarable_flags()) names.push_back(name);
  return fmt::format("{}", fmt::join(names, ", "));
}

// What the handshake line declares (the process's first line, in either format).
struct Handshake {
  std::string name;
  int order = 0;
  unsigned flags = 0;
  bool tangent = false;  // answers steps with their linearisation DΦ (step_tangent)
};

// Validates the handshake; InputError naming the first thing wrong and what is allowed.
Handshake parse_handshake(const std::string& line, const std::string& command) {
  const auto bad = [&](const std::string& what) {
    return InputError(fmt::format(
        "method 'exec': the handshake of '{}' {}; expected a first line like "
        "{{\"name\": \"my_verlet\", \"order\": 2, \"flags\": [\"explicit\", \"symplectic\"]}} "
        "({})",
        command, what, kHelp));
  };
  const json parsed = json::parse(line, nullptr, false);
  if (parsed.is_discarded() || !parsed.is_object()) {
    throw bad(fmt::format("is not a JSON object: '{}'", line.substr(0, 200)));
  }
  Handshake handshake;
  for (const auto& [key, value] : parsed.items()) {
    if (key != "name" && key != "order" && key != "flags" && key != "tangent") {
      throw bad(
          fmt::format("has the unknown key '{}' (allowed: name, order, flags, tangent)", key));
    }
  }
  if (!parsed.contains("name") || !parsed["name"].is_string() ||
      parsed["name"].get<std::string>().empty()) {
    throw bad("has no \"name\" (a non-empty string)");
  }
  handshake.name = parsed["name"].get<std::string>();
  if (!parsed.contains("order") || !parsed["order"].is_number_integer() ||
      parsed["order"].get<long>() < 1 || parsed["order"].get<long>() > 20) {
    throw bad("has no \"order\" (an integer in 1..20, the classical order of accuracy)");
  }
  handshake.order = parsed["order"].get<int>();
  if (!parsed.contains("flags") || !parsed["flags"].is_array()) {
    throw bad(fmt::format("has no \"flags\" (a list of: {})", declarable_flag_names()));
  }
  for (const auto& flag : parsed["flags"]) {
    if (!flag.is_string()) throw bad("has a flag that is not a string");
    bool known = false;
    for (const auto& [name, bit] : declarable_flags()) {
      if (flag.get<std::string>() == name) {
        handshake.flags |= bit;
        known = true;
      }
    }
    if (!known) {
      throw bad(fmt::format("declares the flag '{}' (allowed: {})", flag.get<std::string>(),
                            declarable_flag_names()));
    }
  }
  if (parsed.contains("tangent")) {
    if (!parsed["tangent"].is_boolean()) throw bad("has a \"tangent\" that is not true or false");
    handshake.tangent = parsed["tangent"].get<bool>();
  }
  if (((handshake.flags & kExplicit) != 0) == ((handshake.flags & kImplicit) != 0)) {
    throw bad("declares neither or both of the flags explicit and implicit (exactly one)");
  }
  return handshake;
}

std::string json_numbers(const double* values, Eigen::Index count) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < count; ++i) {
    if (i > 0) out += ',';
    out += fmt::format("{}", values[i]);  // shortest text that reads back to the same double
  }
  return out + "]";
}

std::string binary_frame(int code, std::initializer_list<const Vec*> parts,
                         std::optional<double> scalar = std::nullopt) {
  std::vector<double> values;
  if (scalar) values.push_back(*scalar);
  for (const Vec* part : parts)
    values.insert(values.end(), part->data(), part->data() + part->size());
  std::vector<double> frame = {static_cast<double>(code), static_cast<double>(values.size())};
  frame.insert(frame.end(), values.begin(), values.end());
  return std::string(reinterpret_cast<const char*>(frame.data()), frame.size() * sizeof(double));
}

// A reply with the wrong meaning, size or value: the run's failure row.
StepStatus protocol_failure(const std::string& reason, const std::string& message) {
  return StepStatus::failure(reason, message);
}

class ExecMethod final : public Integrator {
 public:
  // No command: the bare registry entry, which `geomint list` describes and applicable() refuses
  // on every problem (refusal()).
  ExecMethod() = default;
  ExecMethod(std::string command, bool binary, double timeout_s)
      : command_(std::move(command)), binary_(binary), timeout_s_(timeout_s) {
    start();  // the handshake declares order and flags, which info() must know before a run
  }

  MethodInfo info() const override {
    if (command_.empty()) {
      return {"exec", 1, kExplicit | kConservativeOnly,
              fmt::format("a user's process over stdin/stdout ({})", kHelp)};
    }
    // Only ∇V and M⁻¹ cross the pipe: no force, constraint or first-order form reaches the
    // process, so it runs conservative separable problems.
    return {"exec", handshake_.order, handshake_.flags | kConservativeOnly,
            fmt::format("process '{}' ({}), declared by its handshake; {}", handshake_.name,
                        command_, kHelp)};
  }

  std::string refusal() const override {
    if (!command_.empty()) return "";
    return fmt::format(
        "method 'exec' needs a command: exec:cmd=PROGRAM ARGS (with format=json|binary and "
        "timeout=SECONDS; {})",
        kHelp);
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none("a user's process: geomint has no theory of its step");
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    pending_reset_ = true;  // sent with the first step, whose status can report a failure
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    return call_step(problem, state, h, nullptr);
  }

  // The process declared "tangent": true in its handshake; the tangent's Hessian comes from the
  // problem, so the problem must offer one (tangent_applies).
  bool has_step_tangent(const Problem& problem) const override {
    return !command_.empty() && handshake_.tangent && tangent_applies(problem);
  }
  // A reset at `state`, then one step whose answer carries DΦ (2n×2n, row-major).
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    pending_reset_ = true;
    return call_step(problem, state, h, &tangent);
  }

 private:
  StepStatus call_step(const Problem& problem, State& state, double h, Eigen::MatrixXd* tangent) {
    if (command_.empty()) return StepStatus::failure("exec_no_command", refusal());
    try {
      if (!process_ || !process_->running()) start_for_run();
      if (pending_reset_) {
        send_reset(problem, state);
        pending_reset_ = false;
      }
      StepStatus status =
          binary_ ? binary_step(problem, state, h, tangent) : json_step(problem, state, h, tangent);
      if (!status.ok) {
        process_->kill_and_reap();  // its state is unknown now; a later run starts afresh
        return status;
      }
      state.t += h;
      ++counters_.steps;
      return status;
    } catch (const PipeError& error) {
      if (process_) process_->kill_and_reap();
      return StepStatus::failure(error.reason(), error.what());
    } catch (const InputError& error) {
      return StepStatus::failure("exec_handshake", error.what());
    }
  }

  void start() {
    std::vector<std::string> argv = shell_words(command_);
    try {
      process_ = std::make_unique<ChildProcess>(argv);
      handshake_ = parse_handshake(process_->read_line(timeout_s_, "the handshake"), command_);
    } catch (const PipeError& error) {
      if (process_) process_->kill_and_reap();
      throw InputError(fmt::format("method 'exec': {} ({})", error.what(), kHelp));
    }
  }
  // A restart after a failed run must declare what the first start declared.
  void start_for_run() {
    const Handshake declared = handshake_;
    start();
    if (handshake_.order != declared.order || handshake_.flags != declared.flags) {
      throw PipeError("exec_handshake", fmt::format("process '{}' declared another order or other "
                                                    "flags when restarted",
                                                    command_));
    }
  }

  void send_reset(const Problem& problem, const State& state) {
    const Vec& inverse_mass = problem.inverse_mass();
    if (binary_) {
      const Vec t = Vec::Constant(1, state.t);
      process_->write_all(binary_frame(kReset, {&t, &state.q, &state.p, &inverse_mass}), timeout_s_,
                          "reset");
      const auto [code, values] = read_frame("reset");
      if (code != kResult || !values.empty()) {
        throw PipeError("exec_malformed",
                        fmt::format("process '{}' answered reset with frame code {} and {} "
                                    "values; expected code {} with 0 values",
                                    command_, code, values.size(), kResult));
      }
      return;
    }
    process_->write_all(
        fmt::format("{{\"cmd\":\"reset\",\"t\":{},\"q\":{},\"p\":{},\"inverse_mass\":{}}}\n",
                    state.t, json_numbers(state.q.data(), state.q.size()),
                    json_numbers(state.p.data(), state.p.size()),
                    json_numbers(inverse_mass.data(), inverse_mass.size())),
        timeout_s_, "reset");
    const json reply = read_json("reset");
    if (!(reply.is_object() && reply.contains("ok") && reply["ok"] == true)) {
      throw PipeError("exec_malformed", fmt::format("process '{}' answered reset with '{}'; "
                                                    "expected {{\"ok\": true}}",
                                                    command_, reply.dump().substr(0, 200)));
    }
  }

  // One reply line as JSON; PipeError "nan" for NaN/Infinity tokens, "exec_malformed" otherwise.
  json read_json(const std::string& what) {
    const std::string line = process_->read_line(timeout_s_, what);
    json parsed = json::parse(line, nullptr, false);
    if (parsed.is_discarded()) {
      if (line.find("NaN") != std::string::npos || line.find("Infinity") != std::string::npos) {
        throw PipeError("nan", fmt::format("process '{}' answered {} with a non-finite number: "
                                           "'{}'",
                                           command_, what, line.substr(0, 200)));
      }
      throw PipeError("exec_malformed", fmt::format("process '{}' answered {} with a line that is "
                                                    "not JSON: '{}'",
                                                    command_, what, line.substr(0, 200)));
    }
    if (parsed.is_object() && parsed.contains("error")) {
      throw PipeError("exec_error", fmt::format("process '{}' reported an error during {}: {}",
                                                command_, what, parsed["error"].dump()));
    }
    return parsed;
  }

  // `key` of `reply` as exactly `size` finite numbers into `out`.
  StepStatus read_vector(const json& reply, const char* key, Eigen::Index size, Vec& out,
                         const std::string& what) {
    const json& values = reply[key];
    if (!values.is_array()) {
      return protocol_failure(
          "exec_malformed",
          fmt::format("process '{}' answered {}: \"{}\" is not a list", command_, what, key));
    }
    if (static_cast<Eigen::Index>(values.size()) != size) {
      return protocol_failure("exec_size",
                              fmt::format("process '{}' answered {}: \"{}\" has {} numbers, "
                                          "expected {} (the problem's dof)",
                                          command_, what, key, values.size(), size));
    }
    out.resize(size);
    for (Eigen::Index i = 0; i < size; ++i) {
      const json& value = values[static_cast<size_t>(i)];
      if (!value.is_number()) {
        return protocol_failure("exec_malformed",
                                fmt::format("process '{}' answered {}: \"{}\"[{}] is not a number",
                                            command_, what, key, i));
      }
      out[i] = value.get<double>();
      if (!std::isfinite(out[i])) {
        return protocol_failure("nan", fmt::format("process '{}' answered {}: \"{}\"[{}] = {}",
                                                   command_, what, key, i, out[i]));
      }
    }
    return StepStatus::success();
  }

  StepStatus json_step(const Problem& problem, State& state, double h, Eigen::MatrixXd* tangent) {
    const Eigen::Index n = state.q.size();
    process_->write_all(
        fmt::format("{{\"cmd\":\"step\",\"h\":{}{}}}\n", h, tangent ? ",\"tangent\":true" : ""),
        timeout_s_, "step");
    for (;;) {
      const json reply = read_json("step");
      if (!reply.is_object()) {
        return protocol_failure("exec_malformed",
                                fmt::format("process '{}' answered step with '{}', not an object",
                                            command_, reply.dump().substr(0, 200)));
      }
      if (reply.contains("grad")) {
        StepStatus status = read_vector(reply, "grad", n, query_, "a gradient request");
        if (!status.ok) return status;
        eval_gradient(problem, query_, gradient_);
        process_->write_all(
            fmt::format("{{\"grad\":{}}}\n", json_numbers(gradient_.data(), gradient_.size())),
            timeout_s_, "a gradient reply");
        continue;
      }
      if (reply.contains("hessian")) {
        StepStatus status = read_vector(reply, "hessian", n, query_, "a Hessian request");
        if (!status.ok) return status;
        const Eigen::MatrixXd hessian = counted_hessian(problem);
        process_->write_all(
            fmt::format("{{\"hessian\":{}}}\n", json_numbers(hessian.data(), hessian.size())),
            timeout_s_, "a Hessian reply");
        continue;
      }
      if (!reply.contains("q") || !reply.contains("p")) {
        return protocol_failure(
            "exec_malformed",
            fmt::format("process '{}' answered step with '{}'; expected {{\"q\": [...], \"p\": "
                        "[...]}} or a request {{\"grad\": [...]}}",
                        command_, reply.dump().substr(0, 200)));
      }
      StepStatus status = read_vector(reply, "q", n, next_q_, "step");
      if (status.ok) status = read_vector(reply, "p", n, next_p_, "step");
      if (status.ok && tangent) {
        status = reply.contains("tangent")
                     ? read_vector(reply, "tangent", 4 * n * n, flat_tangent_, "a tangent step")
                     : protocol_failure("exec_malformed",
                                        fmt::format("process '{}' answered a tangent step "
                                                    "without \"tangent\"",
                                                    command_));
        if (status.ok) *tangent = row_major(flat_tangent_.data(), 2 * n);
      }
      if (!status.ok) return status;
      state.q = next_q_;
      state.p = next_p_;
      return StepStatus::success();
    }
  }

  // One binary frame: its code and its values (checked finite by the caller).
  std::pair<int, std::vector<double>> read_frame(const std::string& what) {
    const std::string header = process_->read_bytes(2 * sizeof(double), timeout_s_, what);
    double code_count[2];
    std::memcpy(code_count, header.data(), sizeof code_count);
    const double code = code_count[0], count = code_count[1];
    if (!(code == std::floor(code) && code >= kReset && code <= kHessian) ||
        !(count == std::floor(count) && count >= 0 && count <= 1e8)) {
      throw PipeError("exec_malformed",
                      fmt::format("process '{}' answered {} with the frame header ({}, {}); "
                                  "expected a code in {}..{} and a count of values",
                                  command_, what, code, count, kReset, kHessian));
    }
    const auto size = static_cast<size_t>(count);
    const std::string body = process_->read_bytes(size * sizeof(double), timeout_s_, what);
    std::vector<double> values(size);
    if (size > 0) std::memcpy(values.data(), body.data(), body.size());
    if (code == kError) {
      throw PipeError("exec_error",
                      fmt::format("process '{}' reported an error during {}", command_, what));
    }
    return {static_cast<int>(code), std::move(values)};
  }

  StepStatus binary_values(const std::vector<double>& values, size_t expected,
                           const std::string& what) {
    if (values.size() != expected) {
      return protocol_failure("exec_size", fmt::format("process '{}' answered {} with {} values, "
                                                       "expected {}",
                                                       command_, what, values.size(), expected));
    }
    for (size_t i = 0; i < values.size(); ++i) {
      if (!std::isfinite(values[i])) {
        return protocol_failure("nan", fmt::format("process '{}' answered {}: value {} is {}",
                                                   command_, what, i, values[i]));
      }
    }
    return StepStatus::success();
  }

  StepStatus binary_step(const Problem& problem, State& state, double h, Eigen::MatrixXd* tangent) {
    const auto n = static_cast<size_t>(state.q.size());
    process_->write_all(binary_frame(tangent ? kTangentStep : kStep, {}, h), timeout_s_, "step");
    for (;;) {
      const auto [code, values] = read_frame("step");
      if (code == kGradient) {
        StepStatus status = binary_values(values, n, "a gradient request");
        if (!status.ok) return status;
        query_ = Eigen::Map<const Vec>(values.data(), state.q.size());
        eval_gradient(problem, query_, gradient_);
        process_->write_all(binary_frame(kGradient, {&gradient_}), timeout_s_, "a gradient reply");
        continue;
      }
      if (code == kHessian) {
        StepStatus status = binary_values(values, n, "a Hessian request");
        if (!status.ok) return status;
        query_ = Eigen::Map<const Vec>(values.data(), state.q.size());
        const Eigen::MatrixXd hessian = counted_hessian(problem);  // symmetric: any major order
        const Vec flat = Eigen::Map<const Vec>(hessian.data(), hessian.size());
        process_->write_all(binary_frame(kHessian, {&flat}), timeout_s_, "a Hessian reply");
        continue;
      }
      if (code != kResult) {
        return protocol_failure("exec_malformed",
                                fmt::format("process '{}' answered step with frame code {}; "
                                            "expected {} (gradient request) or {} (result)",
                                            command_, code, kGradient, kResult));
      }
      StepStatus status = binary_values(values, tangent ? 2 * n + 4 * n * n : 2 * n, "step");
      if (!status.ok) return status;
      if (tangent) *tangent = row_major(values.data() + 2 * n, static_cast<Eigen::Index>(2 * n));
      state.q = Eigen::Map<const Vec>(values.data(), state.q.size());
      state.p = Eigen::Map<const Vec>(values.data() + n, state.p.size());
      return StepStatus::success();
    }
  }

  // ∇²V at query_, counted as one Hessian evaluation.
  Eigen::MatrixXd counted_hessian(const Problem& problem) {
    ++counters_.hessian_evals;
    return dense_hessian(problem, query_);
  }
  static Eigen::MatrixXd row_major(const double* values, Eigen::Index size) {
    return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        values, size, size);
  }

  const std::string command_;
  const bool binary_ = false;
  const double timeout_s_ = 10;
  Handshake handshake_;
  std::unique_ptr<ChildProcess> process_;
  bool pending_reset_ = false;
  Vec query_, gradient_, next_q_, next_p_, flat_tangent_;
};

}  // namespace

std::unique_ptr<Integrator> make_exec(Params& params) {
  const std::string command =
      params.text("cmd", "",
                  "the program and its arguments, split at blanks as sh splits "
                  "them ('a b' is one word; no shell, no commas)");
  const std::string format =
      params.choice("format", "json", {"json", "binary"},
                    "how numbers cross the pipe: JSON lines, or frames of native doubles");
  const double timeout = params.real("timeout", 10, "seconds the process may take per call",
                                     Range::open_closed(0, 86400));
  // Neither changes a result (the same numbers cross the pipe either way), so a run's canonical
  // spec stays the command alone.
  params.omit_default_from_canonical("format");
  params.omit_default_from_canonical("timeout");
  if (command.empty()) {
    if (params.given("format") || params.given("timeout")) {
      throw InputError(
          fmt::format("method 'exec': no command given; write exec:cmd=PROGRAM ARGS ({})", kHelp));
    }
    return std::make_unique<ExecMethod>();
  }
  std::vector<std::string> words;
  try {
    words = shell_words(command);
  } catch (const InputError& error) {
    throw InputError(fmt::format("method 'exec': cmd: {} ({})", error.what(), kHelp));
  }
  if (words.empty()) {
    throw InputError(
        fmt::format("method 'exec': cmd='{}' names no program (write exec:cmd=PROGRAM ARGS; {})",
                    command, kHelp));
  }
  return std::make_unique<ExecMethod>(command, format == "binary", timeout);
}

}  // namespace geomint
