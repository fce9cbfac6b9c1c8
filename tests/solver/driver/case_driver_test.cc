// One case end to end through the driver, on coarse meshes (seconds each), checked against physics.
#include "solver/driver/case_driver.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <filesystem>
#include <cstdio>
#include <numbers>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "solver/driver/case_summary.h"
#include "solver/io/case_file.h"
#include "solver/io/checkpoint.h"
#include "solver/io/io_error.h"
#include "solver/membrane/membrane_mechanics.h"
#include "solver/mesh/mesh.h"

namespace capsim::driver {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  fs::path p = fs::path(CAPSIM_TEST_TMP) / "driver" / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

RunOptions quiet_in(const fs::path& dir) {
  RunOptions o;
  o.out_dir = dir;
  return o;
}

// Small-deformation theory (Barthès-Biesel & Rallison 1981) for an initially spherical capsule at viscosity
// ratio 1: D12 = 25/4 · μγ̇a/Es with Es = 3 Gs for Ks = 3 Gs, i.e. D12 = 25/12 Ca with our Gs-based Ca, and
// the long axis at 45° to the flow at leading order. At Ca = 0.01 the deformed shape is reached by γ̇t ≈ 0.5;
// later the compressed membrane (τmin < 0 at small Ca, no bending stiffness) wrinkles slowly, so the
// plateau γ̇t ∈ [0.5, 1] is compared.
TEST(CaseDriver, SphereMatchesSmallDeformationTheory) {
  config::CaseConfig c;
  c.aspect_ratio = 1.0;
  c.law = config::MembraneLawKind::NeoHookean;
  c.capillary_number = 0.01;
  c.level = 2;
  c.t_end = 1.0;
  const auto dir = scratch("sphere_small_ca");
  const CaseResult r = run_case(c, quiet_in(dir));
  ASSERT_EQ(r.status, "done") << r.reason;
  const auto series = io::read_case_file(dir / "case.h5").series;
  const double theory = 25.0 / 12.0 * c.capillary_number;
  int checked = 0;
  for (std::size_t i = 0; i < series.size(); ++i) {
    if (series.t[i] < 0.5) continue;
    EXPECT_NEAR(series.D12[i], theory, 0.01 * theory) << "t = " << series.t[i];
    const double theta_deg = series.theta[i] * 180.0 / std::numbers::pi;
    EXPECT_GT(theta_deg, 42.0);
    EXPECT_LE(theta_deg, 45.0);
    ++checked;
  }
  EXPECT_GT(checked, 5);
  EXPECT_LT(std::abs(r.volume_drift), 1e-3);
}

// Both spheroids of the study start with D12 = |a − b|/(a + b) = 1/3 (seed §3.1).
TEST(CaseDriver, SpheroidsStartWithTaylorParameterOneThird) {
  for (double r : {0.5, 2.0}) {
    config::CaseConfig c;
    c.aspect_ratio = r;
    c.level = 2;
    c.t_end = 0.05;
    const auto dir = scratch("d0_" + std::to_string(r));
    ASSERT_EQ(run_case(c, quiet_in(dir)).status, "done");
    const auto series = io::read_case_file(dir / "case.h5").series;
    ASSERT_FALSE(series.empty());
    EXPECT_NEAR(series.D12[0], 1.0 / 3.0, 1e-3) << "a/b = " << r;
    // Prolate: long axis along x1 (θ = 0); oblate: the long in-plane axis is x2 (θ = ±π/2).
    EXPECT_NEAR(std::abs(series.theta[0]), r > 1 ? 0.0 : std::numbers::pi / 2, 1e-6);
  }
}

// The discrete single layer leaks volume; the flux correction removes the leak (up to time-integration error).
TEST(CaseDriver, VolumeCorrectionConservesVolume) {
  config::CaseConfig c;
  c.aspect_ratio = 2.0;
  c.capillary_number = 0.9;
  c.level = 1;
  c.t_end = 4.0;
  c.volume_correction = false;
  const CaseResult leaky = run_case(c, quiet_in(scratch("volume_leaky")));
  c.volume_correction = true;
  const CaseResult kept = run_case(c, quiet_in(scratch("volume_kept")));
  ASSERT_EQ(leaky.status, "done");
  ASSERT_EQ(kept.status, "done");
  std::printf("volume drift over 4 time units, level 1: %.3e without, %.3e with correction\n", leaky.volume_drift,
              kept.volume_drift);
  EXPECT_GT(std::abs(leaky.volume_drift), 1e-3) << "level 1 leaks visibly without the correction";
  EXPECT_LT(std::abs(kept.volume_drift), 1e-2 * std::abs(leaky.volume_drift));
}

// A numerical blow-up is a recorded outcome: status "unstable" with a reason, finite last good state.
TEST(CaseDriver, BlowUpIsRecordedNotThrown) {
  config::CaseConfig c;
  c.aspect_ratio = 2.0;
  c.level = 1;
  c.capillary_number = 0.05;
  c.scheme = config::TimeScheme::Rk2;
  c.dt = 0.5;  // far beyond the explicit stability limit ≈ 0.004 here
  c.t_end = 20.0;
  const auto dir = scratch("blowup");
  CaseResult r;
  ASSERT_NO_THROW(r = run_case(c, quiet_in(dir)));
  EXPECT_EQ(r.status, "unstable");
  EXPECT_FALSE(r.reason.empty());
  EXPECT_LT(r.t_final, c.t_end);
  const auto contents = io::read_case_file(dir / "case.h5");
  for (double d : contents.series.D12) EXPECT_TRUE(std::isfinite(d));
  EXPECT_GE(contents.num_snapshots, 1) << "the last good state is written";
}

// An explicit scheme beyond its stability limit: the instability grows from round-off over some tens of
// steps, so a run can be interrupted and resumed on the way.
config::CaseConfig growing_instability() {
  config::CaseConfig c;
  c.aspect_ratio = 2.0;
  c.level = 1;
  c.capillary_number = 0.05;
  c.scheme = config::TimeScheme::Rk2;
  c.dt_factor = 0.6;  // 2.4 times the automatic rk2 dt; twice it already blows up (time_stepper_test)
  c.t_end = 20.0;
  c.checkpoint_interval = 0.0;
  return c;
}

// Defect 1: the blow-up thresholds come from the reference mesh, so a resumed run fires the same test at
// the same step as the uninterrupted one (it took h_min from the restored, deformed positions).
TEST(CaseDriver, ResumedRunBlowsUpAsTheUninterruptedRun) {
  const config::CaseConfig c = growing_instability();
  const CaseResult full = run_case(c, quiet_in(scratch("resume_blowup_full")));
  ASSERT_EQ(full.status, "unstable") << "the case must blow up for this test to mean anything";
  ASSERT_GT(full.steps, 4) << full.reason;
  std::printf("uninterrupted: %s after %ld steps\n", full.reason.c_str(), full.steps);
  for (long k : {full.steps / 2, full.steps - 2}) {
    const auto dir = scratch("resume_blowup_" + std::to_string(k));
    RunOptions o = quiet_in(dir);
    o.stop_after_steps = k;
    ASSERT_EQ(run_case(c, o).status, "interrupted");
    o.stop_after_steps = 0;
    o.resume = true;
    const CaseResult resumed = run_case(c, o);
    EXPECT_EQ(resumed.status, full.status) << "resumed after " << k << " steps";
    EXPECT_EQ(resumed.reason, full.reason) << "resumed after " << k << " steps";
    EXPECT_EQ(resumed.steps, full.steps) << "resumed after " << k << " steps";
  }
}

// A checkpoint written before a key joined the registry lacks that key's line in its stored case; it must
// still resume (the key takes its default), while a checkpoint of another case is refused. This broke once:
// the level-4 wrinkle run's checkpoint predates numerics.kernel_precision and was refused.
TEST(CaseDriver, CheckpointWithoutALaterKeyResumesAndAnotherCaseIsRefused) {
  const config::CaseConfig c = growing_instability();
  const CaseResult full = run_case(c, quiet_in(scratch("resume_oldkey_full")));
  const auto dir = scratch("resume_oldkey");
  RunOptions o = quiet_in(dir);
  o.stop_after_steps = full.steps / 2;
  ASSERT_EQ(run_case(c, o).status, "interrupted");
  const fs::path file = dir / io::kCheckpointFileName;
  io::Checkpoint cp = io::read_checkpoint(file);
  std::string& stored = cp.strings["case"];
  const auto at = stored.find("kernel_precision = ");
  ASSERT_NE(at, std::string::npos) << stored;
  stored.erase(at, stored.find('\n', at) + 1 - at);  // as written before the key existed
  io::write_checkpoint(file, cp);
  o.stop_after_steps = 0;
  o.resume = true;
  const CaseResult resumed = run_case(c, o);
  EXPECT_EQ(resumed.status, full.status) << resumed.reason;
  EXPECT_EQ(resumed.steps, full.steps);

  // Another value of a key that is written: refused, with a message naming the checkpoint.
  const auto other_dir = scratch("resume_othercase");
  RunOptions p = quiet_in(other_dir);
  p.stop_after_steps = full.steps / 2;
  ASSERT_EQ(run_case(c, p).status, "interrupted");
  config::CaseConfig other = c;
  other.capillary_number = 0.06;
  p.stop_after_steps = 0;
  p.resume = true;
  try {
    run_case(other, p);
    ADD_FAILURE() << "a checkpoint of another case was resumed";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("another case"), std::string::npos) << e.what();
  }
}

double volume_of(const config::CaseConfig& c, const Eigen::Matrix3Xd& x) {
  const auto mesh = mesh::make_capsule_mesh(c.level, c.aspect_ratio, mesh::parse_spheroid_map(c.spheroid_map));
  return membrane::area_and_volume(mesh, x).volume;
}

// Defect 2: the volume test judges the state after the step, so the last good state (checkpoint, last
// snapshot, t_final) keeps the tolerance; it used to be the first state that broke it.
TEST(CaseDriver, LastGoodStateKeepsTheVolumeTolerance) {
  config::CaseConfig c;
  c.aspect_ratio = 2.0;
  c.capillary_number = 0.9;
  c.level = 1;
  c.t_end = 4.0;
  c.volume_correction = false;  // level 1 then leaks > 1e-3 of the volume by t = 4 (VolumeCorrectionConservesVolume)
  c.volume_tolerance = 2e-4;
  const auto dir = scratch("volume_tolerance");
  const CaseResult r = run_case(c, quiet_in(dir));
  ASSERT_EQ(r.status, "unstable");
  EXPECT_NE(r.reason.find("volume"), std::string::npos) << r.reason;
  const double V0 = volume_of(c, mesh::make_capsule_mesh(c.level, c.aspect_ratio).nodes);
  const auto cp = io::read_checkpoint(dir / "checkpoint.h5");
  EXPECT_LE(std::abs(volume_of(c, cp.positions) - V0), c.volume_tolerance * V0) << "the last good state broke it";
  EXPECT_LE(std::abs(r.volume_drift), c.volume_tolerance);
  EXPECT_DOUBLE_EQ(cp.time, r.t_final);
}

// Defect 4: a snapshot reuses the velocity and load of the step's first stage; a case with snapshots
// reports the same flow evaluations and the same time series as without.
TEST(CaseDriver, SnapshotsDoNotChangeTheRun) {
  config::CaseConfig c;
  c.aspect_ratio = 2.0;
  c.capillary_number = 0.3;
  c.level = 1;
  c.t_end = 1.0;
  const auto plain_dir = scratch("snapshots_off"), snap_dir = scratch("snapshots_on");
  const CaseResult plain = run_case(c, quiet_in(plain_dir));
  c.snapshot_interval = 0.25;
  const CaseResult snap = run_case(c, quiet_in(snap_dir));
  ASSERT_EQ(plain.status, "done");
  ASSERT_EQ(snap.status, "done");
  EXPECT_EQ(snap.flow_evaluations, plain.flow_evaluations);
  const auto a = io::read_case_file(plain_dir / "case.h5"), b = io::read_case_file(snap_dir / "case.h5");
  EXPECT_TRUE(a.series == b.series) << "the time series differ";
  EXPECT_EQ(b.num_snapshots, 4);  // t = 0, 0.25, 0.5, 0.75 (the run ends within one dt before t = 1)
}

// Defect 5: a step RKC refuses (more than max_stages stages) is a numerical outcome with its reason, as a
// blow-up is, not an exception that ends the process.
TEST(CaseDriver, RefusedRkcStepIsAnUnstableOutcome) {
  config::CaseConfig c;
  c.aspect_ratio = 2.0;
  c.capillary_number = 1e-4;
  c.level = 1;
  c.scheme = config::TimeScheme::Rkc;
  // ρ ∝ 1/(Ca h_min) ≈ 4e5 at level 1 and Ca 1e-4, so the largest accepted dt (1) needs ≈ 900 stages, beyond
  // the 400 allowed (stages_for: β(s) ≈ 0.653 s² ≥ 1.25 dt ρ).
  c.dt = 1.0;
  c.t_end = 10.0;
  const auto dir = scratch("rkc_refused");
  CaseResult r;
  ASSERT_NO_THROW(r = run_case(c, quiet_in(dir)));
  EXPECT_EQ(r.status, "unstable");
  EXPECT_NE(r.reason.find("stages"), std::string::npos) << r.reason;
  EXPECT_EQ(r.steps, 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "checkpoint.h5"));
}

// Defect 10: an output folder that cannot be created is an output error naming the folder.
TEST(CaseDriver, OutputFolderThatCannotBeCreatedIsAnIoError) {
  const auto dir = scratch("not_a_folder");
  { std::FILE* f = std::fopen((dir / "file").c_str(), "w"); std::fclose(f); }
  config::CaseConfig c;
  c.level = 1;
  c.t_end = 0.1;
  try {
    run_case(c, quiet_in(dir / "file" / "out"));
    FAIL() << "no exception";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("file/out"), std::string::npos) << e.what();
  } catch (const std::exception& e) {
    FAIL() << "not an io::IoError: " << e.what();
  }
}

// Bending stiffness through the driver: the compressed oblate capsule with a stiff bending
// modulus ends done with finite values, the time series carries the bending energy and moment, the stage
// count follows the stiffness, and an interrupted run resumes bitwise onto the uninterrupted one.
TEST(CaseDriver, BendingRunIsStableRecordedAndResumesBitwise) {
  config::CaseConfig c;
  c.aspect_ratio = 0.5;
  c.law = config::MembraneLawKind::NeoHookean;
  c.capillary_number = 0.05;
  c.level = 1;
  c.t_end = 1.0;
  const CaseResult plain = run_case(c, quiet_in(scratch("bending_none")));
  ASSERT_EQ(plain.status, "done") << plain.reason;
  c.bending_modulus = 0.1;
  const auto dir = scratch("bending_full");
  const CaseResult full = run_case(c, quiet_in(dir));
  ASSERT_EQ(full.status, "done") << full.reason;
  EXPECT_GT(full.flow_evaluations, 2 * plain.flow_evaluations) << "the stages must follow the bending stiffness";
  const auto series = io::read_case_file(dir / "case.h5").series;
  ASSERT_GT(series.size(), 10u);
  EXPECT_LT(series.bending_energy.front(), 1e-25) << "the reference has no bending energy (to round-off)";
  for (std::size_t i = 1; i < series.size(); ++i) {
    ASSERT_TRUE(std::isfinite(series.bending_energy[i]) && std::isfinite(series.D12[i]));
    EXPECT_GT(series.bending_energy[i], 0.0) << "t = " << series.t[i];
    EXPECT_GT(series.max_bending_moment[i], 0.0) << "t = " << series.t[i];
  }
  // Interrupted halfway and resumed: the same steps and the same final series, bitwise.
  const auto rdir = scratch("bending_resumed");
  RunOptions o = quiet_in(rdir);
  o.stop_after_steps = full.steps / 2;
  const CaseResult first = run_case(c, o);
  ASSERT_EQ(first.status, "interrupted");
  // The checkpoint carries the phase times of the first invocation, so that the resumed case reports both.
  const io::Checkpoint cp = io::read_checkpoint(rdir / io::kCheckpointFileName);
  ASSERT_TRUE(cp.scalars.count("stokes_s") == 1 && cp.scalars.count("membrane_s") == 1);
  // (At most what the invocation reports: its end-of-run diagnostics evaluate the membrane after the save.)
  EXPECT_GT(cp.scalars.at("stokes_s"), 0.0);
  EXPECT_LE(cp.scalars.at("stokes_s"), first.stokes_s);
  EXPECT_GT(cp.scalars.at("membrane_s"), 0.0);
  EXPECT_LE(cp.scalars.at("membrane_s"), first.membrane_s);
  o.stop_after_steps = 0;
  o.resume = true;
  const CaseResult resumed = run_case(c, o);
  EXPECT_EQ(resumed.steps, full.steps);
  EXPECT_EQ(resumed.flow_evaluations, full.flow_evaluations) << "the cost of both invocations";
  // The phase times too (they were the second invocation's alone): the first invocation's and more.
  EXPECT_GT(resumed.stokes_s, first.stokes_s) << "the phases of both invocations";
  EXPECT_GT(resumed.membrane_s, first.membrane_s);
  EXPECT_TRUE(io::read_case_file(rdir / "case.h5").series == series);
}

// A case option that must not change the case beyond `bound`: `variant` against `base` takes the same evaluations,
// D12 moves at some sample (the option is in use) but by less than `bound` at every one, and `variant` interrupted
// halfway resumes bitwise (its checkpoint carries what the option needs, or the option needs nothing carried).
void expect_same_case_and_bitwise_resume(const config::CaseConfig& base, const config::CaseConfig& variant,
                                         const std::string& name, double bound) {
  const auto base_dir = scratch(name + "_off");
  const CaseResult off = run_case(base, quiet_in(base_dir));
  ASSERT_EQ(off.status, "done") << off.reason;
  const auto dir = scratch(name + "_full");
  const CaseResult full = run_case(variant, quiet_in(dir));
  ASSERT_EQ(full.status, "done") << full.reason;
  EXPECT_EQ(full.flow_evaluations, off.flow_evaluations);
  const auto series = io::read_case_file(dir / "case.h5").series;
  const auto off_series = io::read_case_file(base_dir / "case.h5").series;
  ASSERT_EQ(series.size(), off_series.size());
  double largest = 0.0;
  for (std::size_t i = 0; i < series.size(); ++i) largest = std::max(largest, std::abs(series.D12[i] - off_series.D12[i]));
  EXPECT_GT(largest, 0.0) << name << ": the option is not used";
  EXPECT_LT(largest, bound) << name << ": D12 moved by more than the option allows";
  const auto rdir = scratch(name + "_resumed");
  RunOptions o = quiet_in(rdir);
  o.stop_after_steps = full.steps / 2 + 1;
  ASSERT_EQ(run_case(variant, o).status, "interrupted");
  o.stop_after_steps = 0;
  o.resume = true;
  const CaseResult resumed = run_case(variant, o);
  EXPECT_EQ(resumed.steps, full.steps);
  EXPECT_EQ(resumed.flow_evaluations, full.flow_evaluations);
  EXPECT_TRUE(io::read_case_file(rdir / "case.h5").series == series) << name;
}

// expect_same_case_and_bitwise_resume for an option on an oblate level-2 case (Ca 0.05, γ̇t ≤ 0.6) and on a level-1 case
// with bending stiffness (κ_b = 1e-2, γ̇t ≤ 0.3), whose load is solved on the mass matrix the bending evaluation
// factorised (another path through LoadSolver).
void expect_option_keeps_the_case(const std::string& law, const std::function<void(config::CaseConfig&)>& set_option,
                                  const std::string& name, double bound) {
  config::CaseConfig c;
  c.aspect_ratio = 0.5;
  c.law = config::from_word<config::MembraneLawKind>(law).value();
  c.capillary_number = 0.05;
  c.level = 2;
  c.t_end = 0.6;
  for (const bool bending : {false, true}) {
    if (bending) {
      c.level = 1;
      c.t_end = 0.3;
      c.bending_modulus = 1e-2;
    }
    config::CaseConfig variant = c;
    set_option(variant);
    expect_same_case_and_bitwise_resume(c, variant, name + (bending ? "_bending" : ""), bound);
  }
}

// numerics.load_warm_start carries the previous stage's load into the next solve, but never across a step
// (CapsuleFlow::begin_step): a run interrupted between steps and resumed repeats the uninterrupted one bitwise.
// Its answers stay those of the cold solve to far below the time-step error: D12 within the load tolerance's reach.
TEST(CaseDriver, WarmStartedLoadSolvesResumeBitwise) {
  expect_option_keeps_the_case("neo-hookean", [](config::CaseConfig& c) { c.load_warm_start = true; }, "warm", 1e-9);
}

// numerics.central_symmetry: the same case as without it — in double the operator is the same to round-off (1e-14
// of u), so D12 agrees to round-off over the run; with bending the membrane and the boundary integral use the
// symmetry, the bending evaluation and its load solve the full mesh — and a run interrupted halfway resumes
// bitwise: its checkpoint holds the symmetrised state, from which the driver decides the same way.
TEST(CaseDriver, CentralSymmetryGivesTheSameCaseAndResumesBitwise) {
  expect_option_keeps_the_case("skalak", [](config::CaseConfig& c) { c.central_symmetry = true; }, "central", 1e-11);
}

// flow.viscosity_ratio: the second-kind solve's warm start never crosses a step (CapsuleFlow::begin_step), so a run
// interrupted halfway resumes bitwise, and its GMRES statistics, carried by the checkpoint, are those of the
// uninterrupted run; the summary reports them.
TEST(CaseDriver, ViscosityRatioRunResumesBitwiseWithItsIterationCounts) {
  config::CaseConfig c;
  c.aspect_ratio = 0.5;
  c.law = config::MembraneLawKind::Skalak;
  c.capillary_number = 0.05;
  c.level = 2;
  c.t_end = 0.3;
  c.viscosity_ratio = 5.0;
  const auto dir = scratch("viscosity_full");
  const CaseResult full = run_case(c, quiet_in(dir));
  ASSERT_EQ(full.status, "done") << full.reason;
  EXPECT_GT(full.gmres_iterations_mean, 0.0);
  EXPECT_GE(full.gmres_iterations_max, full.gmres_iterations_mean);
  const CaseSummary summary = CaseSummary::of(c, full);
  EXPECT_EQ(summary.to_json().at("viscosity_ratio").get<double>(), 5.0);
  EXPECT_EQ(summary.to_json().at("gmres_iterations_mean").get<double>(), full.gmres_iterations_mean);
  const auto rdir = scratch("viscosity_resumed");
  RunOptions o = quiet_in(rdir);
  o.stop_after_steps = full.steps / 2 + 1;
  ASSERT_EQ(run_case(c, o).status, "interrupted");
  o.stop_after_steps = 0;
  o.resume = true;
  const CaseResult resumed = run_case(c, o);
  EXPECT_EQ(resumed.steps, full.steps);
  EXPECT_EQ(resumed.flow_evaluations, full.flow_evaluations);
  EXPECT_EQ(resumed.gmres_iterations_mean, full.gmres_iterations_mean);
  EXPECT_EQ(resumed.gmres_iterations_max, full.gmres_iterations_max);
  EXPECT_TRUE(io::read_case_file(rdir / "case.h5").series == io::read_case_file(dir / "case.h5").series);
}

}  // namespace
}  // namespace capsim::driver
