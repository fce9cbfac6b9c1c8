#include "solver/driver/case_driver.h"

#include <chrono>
#include <cmath>
#include <optional>

#include "capsim/version.h"
#include "solver/diagnostics/material_point.h"
#include "solver/diagnostics/time_series.h"
#include "solver/diagnostics/wrinkle.h"
#include "solver/dynamics/capsule_flow.h"
#include "solver/dynamics/time_stepper.h"
#include "solver/io/case_file.h"
#include "solver/io/checkpoint.h"
#include "solver/membrane/membrane_mechanics.h"

namespace capsim::driver {
namespace {

using Clock = std::chrono::steady_clock;

// Runaway velocity: the disturbance velocity of a capsule in unit shear is O(1); a hundred times the
// extent of the capsule per unit time is no physical motion.
constexpr double kMaxDisturbanceSpeed = 100.0;

std::vector<io::Attribute> case_attributes(const config::CaseConfig& c) {
  std::vector<io::Attribute> a;
  a.emplace_back("capillary_number", c.capillary_number);
  a.emplace_back("aspect_ratio", c.aspect_ratio);
  a.emplace_back("law", c.law);
  a.emplace_back("skalak_C", c.skalak_C);
  a.emplace_back("mesh_level", c.level);
  a.emplace_back("config_toml", c.to_toml());
  return a;
}

void write_snapshot(io::CaseWriter& writer, dynamics::CapsuleFlow& flow, const Eigen::Matrix3Xd& x, double t,
                    long step) {
  Eigen::Matrix3Xd v, q;
  flow.velocity(x, v, &q);
  const Eigen::Matrix3Xd n = mesh::node_normals(flow.mesh(), x);
  const Eigen::VectorXd qn = (q.array() * n.array()).colwise().sum().transpose();
  const io::NodeField fields[] = {io::NodeField::scalar("q_n", qn), io::NodeField::vector("q", q),
                                  io::NodeField::vector("velocity", v)};
  writer.write_snapshot(t, step, flow.mesh(), x, fields);
}

// Wrinkle indicators of state x (membrane and load only: no boundary integral, no flow evaluation counted).
// A state the membrane rejects (collapsed element) has none.
std::optional<diagnostics::WrinkleIndicators> measure_wrinkle(dynamics::CapsuleFlow& flow, const Eigen::Matrix3Xd& x,
                                                              int membrane_degree) {
  try {
    Eigen::Matrix3Xd q;
    flow.membrane_load(x, q);
    diagnostics::WrinkleIndicators w;
    w.compressed_area_fraction = diagnostics::compressed_area_fraction(
        flow.mesh(), x, flow.mechanics().principal_tensions(x), membrane_degree);
    w.load_roughness = diagnostics::load_roughness(flow.mesh(), x, q);
    return w;
  } catch (const membrane::DegenerateSurface&) {
    return std::nullopt;
  }
}

// Wrinkle indicators are sampled on this fixed time grid (units of 1/γ̇): often enough to catch a
// transient; each sample costs one membrane evaluation and load solve (O(N), no boundary integral).
constexpr double kWrinkleInterval = 1.0;

}  // namespace

CaseResult run_case(const config::CaseConfig& config, const RunOptions& options) {
  const auto wall0 = Clock::now();
  config.validate();
  std::filesystem::create_directories(options.out_dir);
  const auto case_file = options.out_dir / "case.h5";
  const auto checkpoint_file = options.out_dir / "checkpoint.h5";

  // --- Set up: mesh, membrane, load solver, boundary-integral operator.
  dynamics::CapsuleFlow flow(config);
  const auto& mesh = flow.mesh();
  const double dt = config.dt ? *config.dt : dynamics::automatic_time_step(config, mesh);
  const double V0 = membrane::area_and_volume(mesh, flow.reference()).volume;
  Eigen::Matrix3Xd x = flow.reference();
  double t = 0.0;
  long step = 0;
  diagnostics::TimeSeries series;
  int p_node = diagnostics::choose_material_point(mesh, x);
  const std::string identity = config.to_toml();
  diagnostics::WrinkleIndicators wrinkle_max;  // largest sampled values over the run

  std::optional<io::CaseWriter> writer;
  if (options.resume && std::filesystem::exists(checkpoint_file)) {
    io::Checkpoint cp = io::read_checkpoint(checkpoint_file);
    if (cp.strings["case"] != identity || cp.positions.cols() != mesh.num_nodes())
      throw config::ConfigError(checkpoint_file.string() + ": checkpoint belongs to another case (parameters differ)");
    x = cp.positions;
    t = cp.time;
    step = cp.step;
    series = cp.series;
    p_node = static_cast<int>(cp.scalars["p_node"]);
    wrinkle_max.compressed_area_fraction = cp.scalars["max_compressed_area_fraction"];
    wrinkle_max.load_roughness = cp.scalars["max_load_roughness"];
    writer.emplace(io::CaseWriter::resume(case_file, case_attributes(config), series));
  } else {
    writer.emplace(case_file, case_attributes(config));
  }

  auto save_checkpoint = [&](const Eigen::Matrix3Xd& state, double time, long steps) {
    io::Checkpoint cp;
    cp.positions = state;
    cp.time = time;
    cp.step = steps;
    cp.dt = dt;
    cp.series = series;
    cp.scalars["p_node"] = p_node;
    cp.scalars["max_compressed_area_fraction"] = wrinkle_max.compressed_area_fraction;
    cp.scalars["max_load_roughness"] = wrinkle_max.load_roughness;
    cp.strings["case"] = identity;
    io::write_checkpoint(checkpoint_file, cp);
  };

  // --- March in time.
  CaseResult r;
  r.dt = dt;
  const std::unique_ptr<dynamics::TimeIntegrator> integrator = dynamics::make_integrator(config.scheme);
  Eigen::Matrix3Xd last_good;
  const double h_min = mesh::min_node_spacing(mesh, x);
  const double eps = 1e-9 * dt;
  // Every periodic action sits on a fixed grid of times (multiples of its interval), so a run resumed from a
  // checkpoint checks, samples and saves at exactly the times an uninterrupted run does.
  auto at_or_after = [&](double interval) { return interval > 0 ? std::ceil(t / interval - 1e-9) * interval : INFINITY; };
  auto after = [&](double interval) { return interval > 0 ? (std::floor(t / interval + 1e-9) + 1.0) * interval : INFINITY; };
  double next_check = after(config.check_interval);
  double next_checkpoint = after(config.checkpoint_interval);
  double next_snapshot = at_or_after(config.snapshot_interval);
  double next_sample = config.sample_interval > 0 ? at_or_after(config.sample_interval) : t;
  double next_wrinkle = after(kWrinkleInterval);
  auto sample_wrinkle = [&](const Eigen::Matrix3Xd& state) {
    if (const auto w = measure_wrinkle(flow, state, config.membrane_degree)) {
      wrinkle_max.compressed_area_fraction = std::max(wrinkle_max.compressed_area_fraction, w->compressed_area_fraction);
      wrinkle_max.load_roughness = std::max(wrinkle_max.load_roughness, w->load_roughness);
      return *w;
    }
    return diagnostics::WrinkleIndicators{};
  };
  const long first_step = step;
  auto last_progress = Clock::now();
  diagnostics::ConvergenceOptions conv;
  conv.tol_D12 = conv.tol_tau_min = config.period_tolerance;
  // During the march only a settled steady state may stop the run; the final analysis also classifies a
  // shape that ended stationary to the period tolerance (diagnostics::PeriodOptions).
  const diagnostics::PeriodOptions period_options;
  diagnostics::PeriodOptions final_options;
  final_options.stationary_tolerance = config.period_tolerance;

  while (true) {
    if ((options.stop_requested && options.stop_requested->load()) ||
        (options.stop_after_steps > 0 && step - first_step >= options.stop_after_steps)) {
      save_checkpoint(x, t, step);
      r.status = "interrupted";
      r.reason = "stop requested at t = " + std::to_string(t) + "; resume continues from the checkpoint";
      break;
    }
    // Never step past the hard cap: the last step ends within one dt before t_end.
    if (t + dt > config.t_end + eps) {
      r.status = "done";
      break;
    }
    if (t >= next_snapshot - eps) {
      write_snapshot(*writer, flow, x, t, step);
      next_snapshot += config.snapshot_interval;
    }
    diagnostics::StepRecord rec = diagnostics::measure_step(mesh, x, t, p_node, 0.0);
    last_good = x;
    dynamics::StepInfo info;
    std::string failure;
    try {
      info = integrator->step(flow, x, dt);
    } catch (const membrane::DegenerateSurface& e) {
      failure = e.what();
    }
    if (failure.empty()) {
      if (!x.allFinite()) failure = "non-finite positions";
      else if (!std::isfinite(info.start.max_speed) || info.start.max_speed > kMaxDisturbanceSpeed)
        failure = "runaway velocity |v - v_inf| = " + std::to_string(info.start.max_speed);
      else if (info.max_distortion > 0.5 * h_min)
        failure = "relative displacement of neighbouring nodes " + std::to_string(info.max_distortion) +
                  " in one step exceeds h_min/2";
      else if (std::abs(rec.volume - V0) > config.volume_tolerance * V0)
        failure = "volume changed by " + std::to_string(100.0 * (rec.volume - V0) / V0) + "%";
    }
    if (!failure.empty()) {
      x = last_good;
      r.status = "unstable";
      r.reason = failure + " at t = " + std::to_string(t);
      save_checkpoint(x, t, step);
      writer->write_snapshot(t, step, mesh, x);
      break;
    }
    rec.tau_min = info.start.tau_min;
    if (t >= next_sample - eps) {
      series.push_back(rec);
      writer->append(rec);
      next_sample += config.sample_interval;
    }
    ++step;
    t = step * dt;  // no drift from repeated additions

    if (t >= next_wrinkle - eps) {
      next_wrinkle += kWrinkleInterval;
      sample_wrinkle(x);
    }
    if (t >= next_check - eps) {
      next_check += config.check_interval;
      r.analysis = diagnostics::analyse_periods(series, period_options);
      if (diagnostics::periodic_regime_converged(r.analysis, conv)) {
        r.converged = true;
        r.status = "done";
        break;
      }
    }
    if (t >= next_checkpoint - eps) {
      writer->flush();
      save_checkpoint(x, t, step);
      next_checkpoint += config.checkpoint_interval;
    }
    if (options.progress && Clock::now() - last_progress > std::chrono::seconds(1)) {
      last_progress = Clock::now();
      options.progress({t, config.t_end, step, rec.D12, rec.tau_min,
                        std::chrono::duration<double>(Clock::now() - wall0).count()});
    }
  }

  // --- Output: final analysis and summary attributes.
  r.wrinkle_final = sample_wrinkle(x);
  r.wrinkle_max = wrinkle_max;
  if (!series.empty()) r.analysis = diagnostics::analyse_periods(series, final_options);
  const double V = membrane::area_and_volume(mesh, x).volume;
  r.volume_drift = (V - V0) / V0;
  r.steps = step;
  r.t_final = t;
  r.flow_evaluations = flow.timings().evaluations;
  r.membrane_s = flow.timings().membrane_s;
  r.load_s = flow.timings().load_s;
  r.stokes_s = flow.timings().stokes_s;
  r.case_file = case_file;
  if (r.status == "done") save_checkpoint(x, t, step);
  writer->set_attribute({"status", r.status});
  writer->set_attribute({"reason", r.reason});
  writer->set_attribute({"regime", std::string(diagnostics::to_string(r.analysis.regime))});
  writer->set_attribute({"min_D12", r.analysis.min_D12});
  writer->set_attribute({"max_tau_min", r.analysis.max_tau_min});
  writer->set_attribute({"mean_D12", r.analysis.mean_D12});
  writer->set_attribute({"period", r.analysis.period});
  writer->set_attribute({"volume_drift", r.volume_drift});
  writer->set_attribute({"steps", r.steps});
  writer->set_attribute({"dt", r.dt});
  writer->set_attribute({"t_final", r.t_final});
  writer->set_attribute({"compressed_area_fraction", r.wrinkle_final.compressed_area_fraction});
  writer->set_attribute({"load_roughness", r.wrinkle_final.load_roughness});
  writer->set_attribute({"max_compressed_area_fraction", r.wrinkle_max.compressed_area_fraction});
  writer->set_attribute({"max_load_roughness", r.wrinkle_max.load_roughness});
  writer->close();
  r.wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();
  return r;
}

}  // namespace capsim::driver
