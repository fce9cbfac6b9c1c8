#include "solver/dynamics/flow_benchmark.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "solver/config/case_config.h"
#include "solver/dynamics/capsule_flow.h"
#include "solver/dynamics/cost_model.h"
#include "solver/stokes/source_layout.h"

namespace capsim::dynamics {
namespace {

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A smooth deformation of the reference; `symmetric` keeps x3 → −x3 (even in x3 for x1, x2; odd for x3).
Eigen::Matrix3Xd deformed(const Eigen::Matrix3Xd& ref, bool symmetric) {
  Eigen::Matrix3Xd x = ref;
  for (int i = 0; i < x.cols(); ++i) {
    const double x1 = ref(0, i), x2 = ref(1, i), x3 = ref(2, i);
    const double s3 = symmetric ? x3 * x3 : x3;
    x(0, i) = x1 * (1.0 + 0.08 * std::sin(1.3 * x2 + 0.4 * s3));
    x(1, i) = x2 + 0.05 * std::cos(x1) + 0.03 * s3;
    x(2, i) = x3 * (1.0 - 0.04 * x1);
  }
  return x;
}

// A smooth deformation of the reference that is odd under x → −x as well as symmetric under x3 → −x3 (the
// "central" scene: numerics.central_symmetry evaluates a quarter of the targets, as in a study case with it).
Eigen::Matrix3Xd deformed_centrally_symmetric(const Eigen::Matrix3Xd& ref) {
  Eigen::Matrix3Xd x = ref;
  for (int i = 0; i < x.cols(); ++i) {
    const double x1 = ref(0, i), x2 = ref(1, i), x3 = ref(2, i);
    x(0, i) = x1 * (1.0 + 0.08 * std::sin(1.3 * x1 * x2 + 0.4 * x3 * x3));
    x(1, i) = x2 + 0.05 * std::sin(x1) + 0.03 * x1 * x3 * x3;
    x(2, i) = x3 * (1.0 - 0.04 * x1 * x2);
  }
  return x;
}

// `in_double`: the same case in double precision, timed alternately too (nullptr: the evaluation is double);
// `equal_viscosity`: the same case at λ = 1, likewise (nullptr: λ = 1 already).
FlowBenchScene measure_scene(CapsuleFlow& flow, CapsuleFlow* in_double, CapsuleFlow* equal_viscosity,
                             const Eigen::Matrix3Xd& x, const std::string& name, int repeat, double dt) {
  FlowBenchScene sc;
  sc.name = name;
  sc.nodes = static_cast<int>(x.cols());
  Eigen::Matrix3Xd v, q;
  const FlowEvaluation ev = flow.velocity(x, v, &q);  // warm-up: first-touch allocation, and q for the bare sum
  stokes::SingleLayer& op = flow.single_layer();
  sc.used_symmetry = ev.used_symmetry;
  sc.used_central = ev.used_central;

  // The bare regular sum: the same targets (the ones the evaluation chose) and the same sources, copied so
  // that the evaluations in between cannot touch them.
  const std::vector<int>& ids = op.last_targets();
  sc.targets = static_cast<int>(ids.size());
  sc.sources = op.num_quadrature_points();
  stokes::AlignedVector tx(ids.size()), ty(ids.size()), tz(ids.size()), ux(ids.size()), uy(ids.size()),
      uz(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    tx[k] = x(0, ids[k]);
    ty[k] = x(1, ids[k]);
    tz[k] = x(2, ids[k]);
  }
  const stokes::kernel::Sources s0 = op.build_sources(x, q);
  stokes::SourceArrays src;
  src.x.assign(s0.x, s0.x + s0.n);
  src.y.assign(s0.y, s0.y + s0.n);
  src.z.assign(s0.z, s0.z + s0.n);
  src.qx.assign(s0.qx, s0.qx + s0.n);
  src.qy.assign(s0.qy, s0.qy + s0.n);
  src.qz.assign(s0.qz, s0.qz + s0.n);
  const stokes::kernel::Targets tg{tx.data(), ty.data(), tz.data(), sc.targets};
  const stokes::kernel::Result res{ux.data(), uy.data(), uz.data()};
  const stokes::kernel::FastConfig fast = op.options().fast;
  stokes::kernel::sum_fast(tg, src.sources(), res, fast);  // warm-up

  // Alternate evaluation and bare sum, so that both see the same machine state.
  std::vector<double> eval_ms, bare_ms, double_ms, equal_ms;
  Eigen::Matrix3Xd vd;
  if (in_double) in_double->velocity(x, vd);  // warm-up
  if (equal_viscosity) equal_viscosity->velocity(x, vd);
  const FlowTimings before = flow.timings();
  const SecondKindStatistics gmres_before = flow.second_kind_statistics();
  for (int r = 0; r < repeat; ++r) {
    double t0 = now_ms();
    flow.begin_step();  // no warm start from the previous (identical) evaluation
    flow.velocity(x, v);
    eval_ms.push_back(now_ms() - t0);
    if (in_double) {
      t0 = now_ms();
      in_double->begin_step();  // at λ ≠ 1 a cold solve too, as the timed evaluation's
      in_double->velocity(x, vd);
      double_ms.push_back(now_ms() - t0);
    }
    if (equal_viscosity) {
      t0 = now_ms();
      equal_viscosity->velocity(x, vd);
      equal_ms.push_back(now_ms() - t0);
    }
    t0 = now_ms();
    stokes::kernel::sum_fast(tg, src.sources(), res, fast);
    bare_ms.push_back(now_ms() - t0);
  }
  const FlowTimings after = flow.timings();
  const SecondKindStatistics gmres_after = flow.second_kind_statistics();
  if (equal_viscosity) {
    // The second stage: warm-started from the first stage's solve, on the surface moved by dt v.
    const Eigen::Matrix3Xd x2 = x + dt * v;
    std::vector<double> warm_ms;
    long iterations = 0;
    for (int r = 0; r < repeat; ++r) {
      flow.begin_step();
      flow.velocity(x, v);
      const long before_warm = flow.second_kind_statistics().iterations;
      const double t0 = now_ms();
      flow.velocity(x2, vd);
      warm_ms.push_back(now_ms() - t0);
      iterations += flow.second_kind_statistics().iterations - before_warm;
    }
    sc.evaluation_warm_ms = median(warm_ms);
    sc.gmres_iterations_warm = static_cast<double>(iterations) / repeat;
  }
  sc.repeat = repeat;
  sc.evaluation_ms = median(eval_ms);
  if (in_double) sc.evaluation_double_ms = median(double_ms);
  if (equal_viscosity) sc.evaluation_equal_viscosity_ms = median(equal_ms);
  sc.gmres_iterations = static_cast<double>(gmres_after.iterations - gmres_before.iterations) / repeat;
  sc.layer_applications = static_cast<double>(gmres_after.applications - gmres_before.applications) / repeat;
  sc.regular_sum_ms = median(bare_ms);
  sc.overhead_ratio = sc.evaluation_ms / sc.regular_sum_ms;
  const double per = 1e3 / repeat;
  sc.membrane_ms = per * (after.membrane_s - before.membrane_s);
  sc.bending_ms = per * (after.bending_s - before.bending_s);
  sc.load_ms = per * (after.load_s - before.load_s);
  sc.layout_ms = per * (after.layout_s - before.layout_s);
  sc.regular_ms = per * (after.regular_s - before.regular_s);
  sc.far_ms = per * (after.far_s - before.far_s);
  sc.singular_ms = per * (after.singular_s - before.singular_s);
  sc.near_ms = per * (after.near_s - before.near_s);
  sc.volume_ms = per * (after.volume_s - before.volume_s);
  sc.second_kind_ms = per * (after.second_kind_s - before.second_kind_s);
  sc.layer_prepare_ms = per * (gmres_after.layer_prepare_s - gmres_before.layer_prepare_s);
  sc.layer_layout_ms = per * (gmres_after.layer_layout_s - gmres_before.layer_layout_s);
  sc.layer_regular_ms = per * (gmres_after.layer_regular_s - gmres_before.layer_regular_s);
  sc.layer_singular_ms = per * (gmres_after.layer_singular_s - gmres_before.layer_singular_s);
  sc.layer_near_ms = per * (gmres_after.layer_near_s - gmres_before.layer_near_s);
  sc.deflation_setup_ms = per * (gmres_after.setup_s - gmres_before.setup_s);
  sc.gmres_other_ms = per * (gmres_after.total_s - gmres_before.total_s) -
                      (sc.layer_prepare_ms + sc.layer_layout_ms + sc.layer_regular_ms + sc.layer_singular_ms + sc.layer_near_ms +
                       sc.deflation_setup_ms);
  double mean_eval = 0.0;
  for (double t : eval_ms) mean_eval += t / repeat;
  sc.other_ms = mean_eval - (sc.membrane_ms + sc.bending_ms + sc.load_ms + sc.layout_ms + sc.regular_ms + sc.far_ms +
                             sc.singular_ms + sc.near_ms + sc.volume_ms + sc.second_kind_ms);
  return sc;
}

}  // namespace

config::CaseConfig FlowBenchOptions::scene_with(const std::vector<std::string>& overrides) {
  // The scene's own keys are written out rather than left to the registry's defaults, so that a change of a
  // default does not move what the benchmark measures.
  static const std::string kScene =
      "[capsule]\naspect_ratio = 2.0\nlaw = \"skalak\"\n[flow]\ncapillary_number = 0.3\n[mesh]\nlevel = 3\n"
      "[numerics]\nkernel_precision = \"double\"\n";
  return config::parse_case_config(kScene, "the bench flow scene", overrides);
}

bool FlowBenchOptions::valid(std::string* why) const {
  // The scene's keys are case keys: the registry (case_keys.def) owns their ranges.
  try {
    scene.validate();
  } catch (const config::ConfigError& e) {
    if (why) *why = e.what();
    return false;
  }
  if (repeat < 0 || repeat > 100000) {
    if (why) *why = "repeat must be 0 (automatic) .. 100000, got " + std::to_string(repeat);
    return false;
  }
  return true;
}

FlowBenchReport bench_flow(const FlowBenchOptions& options) {
  if (std::string why; !options.valid(&why)) throw std::invalid_argument("bench flow: " + why);
  const config::CaseConfig& c = options.scene;
  CapsuleFlow flow(c);
  std::unique_ptr<CapsuleFlow> in_double;
  if (c.kernel_precision != "double" || c.double_layer_precision != "double") {
    config::CaseConfig cd = c;
    cd.kernel_precision = "double";
    cd.double_layer_precision = "double";
    in_double = std::make_unique<CapsuleFlow>(cd);
  }
  std::unique_ptr<CapsuleFlow> equal_viscosity;
  if (c.viscosity_ratio != 1.0) {
    config::CaseConfig ce = c;
    ce.viscosity_ratio = 1.0;
    equal_viscosity = std::make_unique<CapsuleFlow>(ce);
  }
  FlowBenchReport report;
  report.level = c.level;
  report.threads = omp_get_max_threads();
  report.isa = stokes::kernel::kernel_isa();
  // Automatic repeat: 40 on level 3 (≈ 1–2 s for the general scene), as many more or fewer as the cost model
  // puts the evaluation cheaper or dearer on this level.
  const bool mixed = c.kernel_precision == "mixed";
  const double per_level = CostModel::evaluation_ms(3, SceneSymmetry::kNone, mixed) /
                           CostModel::evaluation_ms(c.level, SceneSymmetry::kNone, mixed);
  const int repeat = options.repeat > 0 ? options.repeat : std::clamp(static_cast<int>(40.0 * per_level), 5, 400);
  const double dt = automatic_time_step(c, flow.mesh());
  for (const bool symmetric : {true, false})
    report.scenes.push_back(measure_scene(flow, in_double.get(), equal_viscosity.get(),
                                          deformed(flow.reference(), symmetric), symmetric ? "symmetric" : "general",
                                          repeat, dt));
  // The same capsule with numerics.central_symmetry, on a scene that has both symmetries.
  config::CaseConfig cc = c;
  cc.central_symmetry = true;
  CapsuleFlow central(cc);
  std::unique_ptr<CapsuleFlow> central_double, central_equal;
  if (equal_viscosity) {
    config::CaseConfig ce = cc;
    ce.viscosity_ratio = 1.0;
    central_equal = std::make_unique<CapsuleFlow>(ce);
  }
  if (in_double) {
    cc.kernel_precision = "double";
    cc.double_layer_precision = "double";
    central_double = std::make_unique<CapsuleFlow>(cc);
  }
  report.scenes.push_back(measure_scene(central, central_double.get(), central_equal.get(),
                                        deformed_centrally_symmetric(central.reference()), "central", repeat, dt));
  return report;
}

}  // namespace capsim::dynamics
