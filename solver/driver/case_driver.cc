#include "solver/driver/case_driver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <system_error>

#include "solver/diagnostics/material_point.h"
#include "solver/diagnostics/membrane_spin.h"
#include "solver/diagnostics/orientation_regime.h"
#include "solver/diagnostics/time_series.h"
#include "solver/driver/case_summary.h"
#include "solver/driver/snapshot_fields.h"
#include "solver/dynamics/capsule_flow.h"
#include "solver/dynamics/time_stepper.h"
#include "solver/dynamics/viscosity_contrast.h"
#include "solver/io/case_file.h"
#include "solver/io/checkpoint.h"
#include "solver/io/io_error.h"
#include "solver/membrane/membrane_mechanics.h"

namespace capsim::driver {
namespace {

using Clock = std::chrono::steady_clock;

// Runaway velocity: the disturbance velocity of a capsule in unit shear is O(1); a hundred times the
// extent of the capsule per unit time is no physical motion.
constexpr double kMaxDisturbanceSpeed = 100.0;

// Wrinkle indicators are sampled on this fixed time grid (units of 1/γ̇): often enough to catch a
// transient; each sample costs one membrane evaluation and load solve (O(N), no boundary integral).
constexpr double kWrinkleInterval = 1.0;

std::vector<io::Attribute> case_attributes(const config::CaseConfig& c) {
  std::vector<io::Attribute> a;
  a.emplace_back("capillary_number", c.capillary_number);
  a.emplace_back("aspect_ratio", c.aspect_ratio);
  a.emplace_back("law", std::string(config::word_of(c.law)));
  a.emplace_back("skalak_C", c.skalak_C);
  a.emplace_back("mesh_level", c.level);
  a.emplace_back("bending_modulus", c.bending_modulus);
  a.emplace_back("config_toml", c.to_toml());
  return a;
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
    const auto relief = diagnostics::WrinkleWavelength(flow.mesh()).measure(x);
    w.wrinkle_wavelength = relief.wavelength;
    w.wrinkle_amplitude = relief.amplitude;
    return w;
  } catch (const membrane::DegenerateSurface&) {
    return std::nullopt;
  }
}

// One run of one case, in the phases of the method. Each phase is a member function; run() calls them in
// order. The state that a checkpoint carries (x, t, step, series, p_node, wrinkle_max) lives here, so a
// resumed run continues exactly where the interrupted one stopped.
class CaseRun {
 public:
  CaseRun(const config::CaseConfig& config, const RunOptions& options)
      : config_(config), options_(options), wall0_(Clock::now()) {}

  CaseResult run() {
    set_up();
    restore_or_start();
    march();
    finish();
    output();
    return r_;
  }

 private:
  // --- Set up: output folder, mesh, membrane, load solver, boundary-integral operator, time step and the
  // blow-up thresholds, all from the reference shape (a resumed run gets the same ones).
  void set_up() {
    config_.validate();
    std::error_code ec;
    std::filesystem::create_directories(options_.out_dir, ec);
    if (ec) throw io::IoError(options_.out_dir, "cannot create the output folder: " + ec.message());
    case_file_ = options_.out_dir / "case.h5";
    checkpoint_file_ = options_.out_dir / io::kCheckpointFileName;
    flow_.emplace(config_);
    dt_ = config_.dt ? *config_.dt : dynamics::automatic_time_step(config_, mesh());
    V0_ = membrane::area_and_volume(mesh(), flow_->reference()).volume;
    h_min_ = mesh::min_node_spacing(mesh(), flow_->reference());
    eps_ = 1e-9 * dt_;
    integrator_ = dynamics::make_integrator(config_.scheme, config_.rkc_safety);
    identity_ = config_.to_toml();
  }

  // --- Restore (from the checkpoint, with --resume) or start from the reference shape.
  void restore_or_start() {
    x_ = flow_->reference();
    p_node_ = diagnostics::choose_material_point(mesh(), x_);
    double spin = 0.0;  // the membrane's spin about its axis (membrane_spin.h) of the state x_: 0 at the start
    if (options_.resume && std::filesystem::exists(checkpoint_file_)) {
      io::Checkpoint cp;
      try {
        cp = io::read_checkpoint(checkpoint_file_);
      } catch (const io::IoError& e) {
        throw config::ConfigError(std::string(e.what()) + " (remove it to start afresh)");  // bad input, not output
      }
      if (!same_case(cp.strings["case"]) || cp.positions.cols() != mesh().num_nodes())
        throw config::ConfigError(checkpoint_file_.string() + ": checkpoint belongs to another case (parameters differ)");
      x_ = cp.positions;
      t_ = cp.time;
      step_ = cp.step;
      series_ = cp.series;
      p_node_ = static_cast<int>(cp.scalars["p_node"]);
      // The spin of the checkpointed state (it accumulates over every step, so the sampled series does not hold
      // it). A checkpoint from before the spin has none: the spin restarts from 0 at the resumed state (the rows
      // before read as NaN, so no rate is taken across the restart).
      if (const auto s = cp.scalars.find("spin"); s != cp.scalars.end()) spin = s->second;
      wrinkle_max_.compressed_area_fraction = cp.scalars["max_compressed_area_fraction"];
      wrinkle_max_.load_roughness = cp.scalars["max_load_roughness"];
      // The most wrinkled sample so far (absent in checkpoints from before the wavelength: none yet).
      if (const auto a = cp.scalars.find("max_wrinkle_amplitude"); a != cp.scalars.end()) {
        wrinkle_max_.wrinkle_amplitude = a->second;
        wrinkle_max_.wrinkle_wavelength = cp.scalars["wrinkle_wavelength_of_max"];
      }
      // The cost of the invocations before (absent in checkpoints from before they were kept: 0), so that a
      // resumed case reports what the uninterrupted one would (the campaigns' core-hours rest on it).
      evaluations_before_ = static_cast<long>(cp.scalars["flow_evaluations"]);
      wall_before_ = cp.scalars["wall_s"];
      // The same for the phase times (absent from older checkpoints: 0, so a case resumed from such a checkpoint
      // reports the phases of its later invocations only, while wall_s covers all).
      membrane_before_ = cp.scalars["membrane_s"];
      load_before_ = cp.scalars["load_s"];
      stokes_before_ = cp.scalars["stokes_s"];
      // GMRES iterations of the viscosity-ratio solves before (written only when λ ≠ 1: 0 otherwise).
      gmres_before_.solves = static_cast<long>(cp.scalars["gmres_solves"]);
      gmres_before_.iterations = static_cast<long>(cp.scalars["gmres_iterations"]);
      gmres_before_.max_iterations = static_cast<int>(cp.scalars["gmres_iterations_max"]);
      writer_.emplace(io::CaseWriter::resume(case_file_, case_attributes(config_), series_));
    } else {
      writer_.emplace(case_file_, case_attributes(config_));
    }
    // A state that starts mirror-symmetric (every study case: the revolution axis in the shear plane) is
    // kept exactly so after each step (mesh::symmetrise says why); a resumed run decides the same way from
    // its checkpoint, which holds a symmetrised state.
    keep_mirror_ = mesh::is_mirror_symmetric(mesh(), x_, 1e-12);
    // With numerics.central_symmetry the point symmetry x → −x too (the flow's boundary integral then
    // evaluates one node of each orbit). The reference spheroid has it to round-off only (its nodes at
    // θ and π − θ are mapped separately), hence the tolerance; the first step's symmetrisation makes it exact.
    keep_central_ = config_.central_symmetry && mesh::is_centrally_symmetric(mesh(), x_, 1e-12);
    before_ = x_;
    record_ = diagnostics::measure_step(mesh(), x_, t_, p_node_, 0.0);
    record_.spin = spin;
    before_spin_ = spin;
    first_step_ = step_;
    // Every periodic action sits on a fixed grid of times (multiples of its interval), so a run resumed from
    // a checkpoint checks, samples and saves at exactly the times an uninterrupted run does.
    next_check_ = after(config_.check_interval);
    next_checkpoint_ = after(config_.checkpoint_interval);
    next_snapshot_ = at_or_after(config_.snapshot_interval);
    next_sample_ = config_.sample_interval > 0 ? at_or_after(config_.sample_interval) : t_;
    next_wrinkle_ = after(kWrinkleInterval);
    convergence_ = diagnostics::stop_test_options(config_.stop_test, config_.period_tolerance);
    // The tilt is held to the period tolerance taken as an angle (radians, here in degrees): a turn of the axis
    // by δ moves the capsule's ends by about δ, as a change δ of D12 moves its boundary.
    tilt_tolerance_ = config_.period_tolerance * 180.0 / std::numbers::pi;
  }

  // --- March in time until an interrupt, t_end, a blow-up or a converged periodic regime.
  void march() {
    while (true) {
      if ((options_.stop_requested && options_.stop_requested->load()) ||
          (options_.stop_after_steps > 0 && step_ - first_step_ >= options_.stop_after_steps)) {
        save_checkpoint();
        r_.status = "interrupted";
        r_.reason = "stop requested at t = " + std::to_string(t_) + "; resume continues from the checkpoint";
        return;
      }
      // Never step past the hard cap: the last step ends within one dt before t_end.
      if (t_ + dt_ > config_.t_end + eps_) {
        r_.status = "done";
        return;
      }
      if (!advance()) return;
      if (periodic_actions()) return;
    }
  }

  // One step x_n → x_{n+1} and the blow-up tests. Each test judges a state by what is known of it: the
  // velocity of x_n (the step's first stage), the displacement of the step, and x_{n+1} itself (finite,
  // volume). A state is accepted only when it passed them, so the last good state never broke a tolerance.
  // Returns false after a blow-up (status unstable, the last good state restored, checkpointed and written).
  bool advance() {
    const bool snapshot_due = t_ >= next_snapshot_ - eps_;
    next_ = x_;
    dynamics::StepInfo info;
    std::string failure;
    bool stepped = false;
    try {
      flow_->begin_step();  // no load carried into a step: a resumed run repeats this one bitwise
      info = integrator_->step(*flow_, next_, dt_, snapshot_due ? &start_ : nullptr);
      if (keep_central_)
        mesh::symmetrise(mesh(), next_, keep_mirror_, true);
      else if (keep_mirror_)
        mesh::symmetrise(mesh(), next_);
      stepped = true;
    } catch (const membrane::DegenerateSurface& e) {
      failure = e.what();
    } catch (const dynamics::StepRejected& e) {  // dt too large for this state: a numerical outcome too
      failure = e.what();
    } catch (const dynamics::SecondKindNotConverged& e) {  // the viscosity-ratio solve failed: likewise
      failure = e.what();
    }
    if (stepped && (!std::isfinite(info.start.max_speed) || info.start.max_speed > kMaxDisturbanceSpeed)) {
      // x_n itself moves at a runaway speed: the last good state is the one before it.
      return blow_up("runaway velocity |v - v_inf| = " + std::to_string(info.start.max_speed), before_,
                     step_ == first_step_ ? step_ : step_ - 1);
    }
    if (!failure.empty()) return blow_up(failure, x_, step_);
    const double t_next = static_cast<double>(step_ + 1) * dt_;  // no drift from repeated additions
    if (!next_.allFinite()) return blow_up("non-finite positions", x_, step_);
    if (info.max_distortion > 0.5 * h_min_)
      return blow_up("relative displacement of neighbouring nodes " + std::to_string(info.max_distortion) +
                         " in one step exceeds h_min/2 = " + std::to_string(0.5 * h_min_),
                     x_, step_);
    diagnostics::StepRecord next_record = diagnostics::measure_step(mesh(), next_, t_next, p_node_, 0.0);
    next_record.spin = diagnostics::advance_spin(record_.spin, mesh(), x_, next_);
    if (std::abs(next_record.volume - V0_) > config_.volume_tolerance * V0_)
      return blow_up("volume changed by " + std::to_string(100.0 * (next_record.volume - V0_) / V0_) + "%", x_,
                     step_);

    // x_n passed every test: record it, then accept x_{n+1}.
    record_.tau_min = info.start.tau_min;
    record_.bending_energy = info.start.bending_energy;
    record_.max_bending_moment = info.start.max_bending_moment;
    if (snapshot_due) {
      writer_->write_snapshot(t_, step_, mesh(), x_,
                              snapshot_fields(mesh(), flow_->mechanics(), x_, start_, config_.membrane_degree),
                              &record_);
      next_snapshot_ += config_.snapshot_interval;
    }
    if (t_ >= next_sample_ - eps_) {
      series_.push_back(record_);
      writer_->append(record_);
      next_sample_ += config_.sample_interval;
    }
    std::swap(before_, x_);
    std::swap(x_, next_);
    before_spin_ = record_.spin;
    record_ = next_record;
    ++step_;
    t_ = t_next;
    return true;
  }

  // A blow-up of the state at t_: the run ends unstable at @p good (step @p good_step), which becomes the
  // state of the checkpoint and the last snapshot.
  bool blow_up(const std::string& failure, const Eigen::Matrix3Xd& good, long good_step) {
    r_.status = "unstable";
    r_.reason = failure + " at t = " + std::to_string(t_);
    if (&good == &before_) record_.spin = before_spin_;  // the checkpoint carries the spin of the state it holds
    if (&good != &x_) x_ = good;
    step_ = good_step;
    t_ = static_cast<double>(step_) * dt_;
    save_checkpoint();
    writer_->write_snapshot(t_, step_, mesh(), x_);
    return false;
  }

  // The actions on their time grids after an accepted step: wrinkle sample, convergence check, checkpoint,
  // progress. Returns true when the periodic regime has converged (the run is done).
  bool periodic_actions() {
    if (t_ >= next_wrinkle_ - eps_) {
      next_wrinkle_ += kWrinkleInterval;
      sample_wrinkle();
    }
    if (t_ >= next_check_ - eps_) {
      next_check_ += config_.check_interval;
      r_.analysis = diagnostics::analyse_periods(series_);
      // Off the plane the regime must also have repeated with the same tilt (orientation_converged: always true
      // for an axis in the plane, whose stop is the in-plane test alone).
      if (diagnostics::periodic_regime_converged(r_.analysis, convergence_) &&
          diagnostics::orientation_converged(series_, r_.analysis, tilt_tolerance_)) {
        r_.converged = true;
        r_.status = "done";
        return true;
      }
    }
    if (t_ >= next_checkpoint_ - eps_) {
      writer_->flush();
      save_checkpoint();
      next_checkpoint_ += config_.checkpoint_interval;
    }
    if (options_.progress && Clock::now() - last_progress_ > std::chrono::seconds(1)) {
      last_progress_ = Clock::now();
      options_.progress({t_, config_.t_end, step_, record_.D12, series_.empty() ? 0.0 : series_.tau_min.back(),
                         std::chrono::duration<double>(Clock::now() - wall0_).count()});
    }
    return false;
  }

  // --- Finish: final wrinkle sample, period analysis, volume drift, counts and timings.
  void finish() {
    r_.wrinkle_final = sample_wrinkle();
    r_.wrinkle_max = wrinkle_max_;
    // The final analysis also classifies a shape that ended stationary to the period tolerance; during the
    // march only a settled steady state may stop the run (diagnostics::PeriodOptions).
    diagnostics::PeriodOptions final_analysis;
    final_analysis.stationary_tolerance = config_.period_tolerance;
    if (!series_.empty()) r_.analysis = diagnostics::analyse_periods(series_, final_analysis);
    const double V = membrane::area_and_volume(mesh(), x_).volume;
    r_.volume_drift = (V - V0_) / V0_;
    r_.dt = dt_;
    r_.steps = step_;
    r_.t_final = t_;
    r_.flow_evaluations = evaluations_before_ + flow_->timings().evaluations;
    r_.membrane_s = membrane_s();
    r_.load_s = load_s();
    r_.stokes_s = stokes_s();
    const dynamics::SecondKindStatistics gmres = gmres_statistics();
    r_.gmres_iterations_mean = gmres.mean_iterations();
    r_.gmres_iterations_max = gmres.max_iterations;
    if (!series_.empty()) {
      const bool period = !r_.analysis.periods.empty();
      r_.final_tilt = diagnostics::final_tilt(series_, period ? r_.analysis.periods.front().t_begin : t_,
                                              period ? r_.analysis.periods.front().t_end : t_);
      // The spin rate over the same window (NaN without a period; solver/README.md §5 says what it is worth for a
      // window shorter than a revolution of the membrane).
      if (period)
        r_.final_spin_rate = diagnostics::final_spin_rate(series_, r_.analysis.periods.front().t_begin,
                                                          r_.analysis.periods.front().t_end);
      const diagnostics::TiltGrowth growth = diagnostics::tilt_growth_rate(series_, r_.analysis);
      r_.tilt_growth_rate = growth.rate;
      r_.tilt_growth_rate_error = growth.error;
      // The published name of what the capsule ends doing: the in-plane regime itself while the axis stays in
      // the plane (every in-plane case), else rolling, wobbling, kayaking, oscillating-swinging (§5).
      r_.analysis.regime = diagnostics::classify_regime(series_, r_.analysis);
    }
    r_.case_file = case_file_;
  }

  // --- Output: the final checkpoint of a finished case and the summary as the case file's attributes.
  void output() {
    if (r_.status == "done") save_checkpoint();
    r_.wall_s = wall_before_ + std::chrono::duration<double>(Clock::now() - wall0_).count();
    for (const auto& a : summary_attributes(CaseSummary::of(config_, r_))) writer_->set_attribute(a);
    writer_->close();
    r_.wall_s = wall_before_ + std::chrono::duration<double>(Clock::now() - wall0_).count();
  }

  void save_checkpoint() {
    io::Checkpoint cp;
    cp.positions = x_;
    cp.time = t_;
    cp.step = step_;
    cp.dt = dt_;
    cp.series = series_;
    cp.scalars["p_node"] = p_node_;
    cp.scalars["spin"] = record_.spin;
    cp.scalars["max_compressed_area_fraction"] = wrinkle_max_.compressed_area_fraction;
    cp.scalars["max_load_roughness"] = wrinkle_max_.load_roughness;
    cp.scalars["max_wrinkle_amplitude"] = wrinkle_max_.wrinkle_amplitude;
    cp.scalars["wrinkle_wavelength_of_max"] = wrinkle_max_.wrinkle_wavelength;
    cp.scalars["flow_evaluations"] = static_cast<double>(evaluations_before_ + flow_->timings().evaluations);
    cp.scalars["wall_s"] = wall_before_ + std::chrono::duration<double>(Clock::now() - wall0_).count();
    cp.scalars["membrane_s"] = membrane_s();
    cp.scalars["load_s"] = load_s();
    cp.scalars["stokes_s"] = stokes_s();
    if (config_.viscosity_ratio != 1.0) {  // a λ = 1 checkpoint keeps its fields
      const dynamics::SecondKindStatistics gmres = gmres_statistics();
      cp.scalars["gmres_solves"] = static_cast<double>(gmres.solves);
      cp.scalars["gmres_iterations"] = static_cast<double>(gmres.iterations);
      cp.scalars["gmres_iterations_max"] = gmres.max_iterations;
    }
    cp.strings["case"] = identity_;
    io::write_checkpoint(checkpoint_file_, cp);
  }

  diagnostics::WrinkleIndicators sample_wrinkle() {
    if (const auto w = measure_wrinkle(*flow_, x_, config_.membrane_degree)) {
      wrinkle_max_.compressed_area_fraction = std::max(wrinkle_max_.compressed_area_fraction, w->compressed_area_fraction);
      wrinkle_max_.load_roughness = std::max(wrinkle_max_.load_roughness, w->load_roughness);
      // The wavelength of the most wrinkled sample (largest relief), not the largest wavelength: a tumbling
      // capsule wrinkles in one phase of its period and is smooth in another, so the final state may show none.
      if (std::isfinite(w->wrinkle_amplitude) &&
          !(w->wrinkle_amplitude <= wrinkle_max_.wrinkle_amplitude)) {  // NaN so far: take it
        wrinkle_max_.wrinkle_amplitude = w->wrinkle_amplitude;
        wrinkle_max_.wrinkle_wavelength = w->wrinkle_wavelength;
      }
      return *w;
    }
    return {};
  }

  /// A checkpoint's case is this one when its stored TOML, read by today's parser, gives the same effective
  /// configuration: a key added to the registry after the checkpoint was written takes its default there, so
  /// an old checkpoint still resumes (its text lacks the key) while any differing value is refused.
  bool same_case(const std::string& stored) const {
    if (stored == identity_) return true;
    try {
      return config::parse_case_config(stored, checkpoint_file_.string()).to_toml() == identity_;
    } catch (const config::ConfigError&) {
      return false;  // a key the registry no longer has, or a value it no longer accepts
    }
  }

  double at_or_after(double interval) const {
    return interval > 0 ? std::ceil(t_ / interval - 1e-9) * interval : INFINITY;
  }
  double after(double interval) const {
    return interval > 0 ? (std::floor(t_ / interval + 1e-9) + 1.0) * interval : INFINITY;
  }
  const mesh::SurfaceMesh& mesh() const { return flow_->mesh(); }

  const config::CaseConfig& config_;
  const RunOptions& options_;
  const Clock::time_point wall0_;
  Clock::time_point last_progress_ = Clock::now();

  // Set up.
  std::filesystem::path case_file_, checkpoint_file_;
  std::optional<dynamics::CapsuleFlow> flow_;
  std::unique_ptr<dynamics::TimeIntegrator> integrator_;
  double dt_ = 0, V0_ = 0, h_min_ = 0, eps_ = 0;
  std::string identity_;
  diagnostics::ConvergenceOptions convergence_;
  double tilt_tolerance_ = 0;  // degrees, the off-plane part of the stop test
  std::optional<io::CaseWriter> writer_;

  // The state a checkpoint carries.
  Eigen::Matrix3Xd x_;
  double t_ = 0.0;
  long step_ = 0;
  long evaluations_before_ = 0;  // flow evaluations, wall and phase times of the invocations before a resume
  double wall_before_ = 0.0;
  double membrane_before_ = 0.0, load_before_ = 0.0, stokes_before_ = 0.0;
  dynamics::SecondKindStatistics gmres_before_;
  // The GMRES iterations of this and the earlier invocations.
  [[nodiscard]] dynamics::SecondKindStatistics gmres_statistics() const {
    dynamics::SecondKindStatistics g = flow_->second_kind_statistics();
    g.solves += gmres_before_.solves;
    g.iterations += gmres_before_.iterations;
    g.max_iterations = std::max(g.max_iterations, gmres_before_.max_iterations);
    return g;
  }
  // The phase times of all invocations (membrane: elastic + bending), for the result and the checkpoint.
  [[nodiscard]] double membrane_s() const {
    return membrane_before_ + flow_->timings().membrane_s + flow_->timings().bending_s;
  }
  [[nodiscard]] double load_s() const { return load_before_ + flow_->timings().load_s; }
  [[nodiscard]] double stokes_s() const { return stokes_before_ + flow_->timings().stokes_s; }
  diagnostics::TimeSeries series_;
  int p_node_ = 0;
  bool keep_mirror_ = false;  // the state started mirror-symmetric: keep it exactly so (restore_or_start)
  bool keep_central_ = false;  // numerics.central_symmetry and a centrally symmetric start: keep that too
  diagnostics::WrinkleIndicators wrinkle_max_;  // largest sampled values over the run

  // The march.
  long first_step_ = 0;
  Eigen::Matrix3Xd before_, next_;  // x_{n-1} (the last good state if x_n runs away) and x_{n+1}
  diagnostics::StepRecord record_;  // diagnostics of x_n, measured when it was accepted
  double before_spin_ = 0.0;        // the spin of x_{n-1} (before_), should x_n run away
  dynamics::StartFields start_;     // v and q on x_n, kept from the first stage for a snapshot
  double next_check_ = 0, next_checkpoint_ = 0, next_snapshot_ = 0, next_sample_ = 0, next_wrinkle_ = 0;

  CaseResult r_;
};

}  // namespace

CaseResult run_case(const config::CaseConfig& config, const RunOptions& options) {
  return CaseRun(config, options).run();
}

}  // namespace capsim::driver
