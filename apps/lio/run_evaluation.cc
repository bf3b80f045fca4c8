#include "run_evaluation.h"

#include <glog/logging.h>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <string>

#include "ctlio/sim/extrinsic_error.h"

namespace ctlio::lioapp {

namespace {

// With the extrinsic estimated or a perturbed nominal one: the starting and final extrinsic
// errors against the truth (rotation angle [deg], translation [cm]; sim/extrinsic_error.h), the
// final marginal σ per axis [ρ: cm; φ: deg] and whether the final error δ = Log(T_true·T_est⁻¹)
// lies within 3σ on every rotation / translation axis.
void WriteExtrinsicEvaluation(const RunSummary& run, std::ostream& ev) {
  const bool perturbed =
      run.true_extrinsic &&
      (run.true_extrinsic->Matrix() - run.initial_extrinsic.Matrix()).norm() > 0.0;
  if (!run.extrinsic_estimated && !perturbed) return;
  ev << "extrinsic_estimated " << (run.extrinsic_estimated ? 1 : 0) << "\n";
  const SE3& T = run.final_extrinsic;
  const Eigen::Quaterniond q = T.quaternion();
  ev << "extrinsic_final_xyz_qxyzw " << T.translation().x() << ' ' << T.translation().y() << ' '
     << T.translation().z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << "\n";
  if (run.extrinsic_estimated) {
    const Vec6& s = run.final_extrinsic_sigma;
    ev << "extrinsic_sigma_cm " << 100 * s[0] << ' ' << 100 * s[1] << ' ' << 100 * s[2]
       << "\nextrinsic_sigma_deg " << s[3] * 180 / M_PI << ' ' << s[4] * 180 / M_PI << ' '
       << s[5] * 180 / M_PI << "\n";
  }
  if (!run.true_extrinsic) return;
  const sim::ExtrinsicErrorSize e0 =
      sim::MeasureExtrinsicError(run.initial_extrinsic, *run.true_extrinsic);
  const sim::ExtrinsicErrorSize e1 = sim::MeasureExtrinsicError(T, *run.true_extrinsic);
  ev << "extrinsic_initial_error_deg " << e0.rotation_deg << "\nextrinsic_initial_error_cm "
     << 100 * e0.translation_m << "\nextrinsic_error_deg " << e1.rotation_deg
     << "\nextrinsic_error_cm " << 100 * e1.translation_m << "\n";
  if (run.extrinsic_estimated) {
    const sim::SigmaCoverage c =
        sim::CoveredBySigma(T, *run.true_extrinsic, run.final_extrinsic_sigma);
    ev << "extrinsic_translation_within_3sigma " << (c.translation ? 1 : 0)
       << "\nextrinsic_rotation_within_3sigma " << (c.rotation ? 1 : 0) << "\n";
  }
}

}  // namespace

void WriteRunEvaluation(const RunSummary& run,
                        const std::optional<RecommendedCalibration>& recommended,
                        const std::vector<io::StampedPose>* truth, std::ostream& ev) {
  ev << "source " << run.source << "\nmethod " << run.method << "\nscans " << run.scans.size()
     << "\nfailed_scans " << run.failed << "\ndegenerate_scans " << run.degenerate
     << "\ndegenerate_direction_scans " << run.degenerate_direction_scans << "\nimu_gap_scans "
     << run.imu_gaps << "\nmedian_ms " << run.median_ms << "\np95_ms " << run.p95_ms << "\nmax_ms "
     << run.max_ms << "\nmedian_cpu_ms " << run.median_cpu_ms << "\np95_cpu_ms " << run.p95_cpu_ms
     << "\nmedian_preprocess_ms " << run.median_preprocess_ms << "\nmedian_associate_ms "
     << run.median_associate_ms << "\nmedian_solve_ms " << run.median_solve_ms << "\nmedian_map_ms "
     << run.median_map_ms << "\nmedian_marginalize_ms " << run.median_marginalize_ms
     << "\npeak_rss_mb " << run.peak_rss_kb / 1024.0 << "\nextrinsic_origin \""
     << run.extrinsic_origin << "\"\nimu_samples_rejected " << run.imu_rejected
     << "\npoints_dropped_out_of_interval " << run.points_dropped << "\nscans_skipped "
     << run.scans_skipped << "\nconstant_imu_scans " << run.constant_imu_scans << "\nlidar_gaps "
     << run.lidar_gaps << "\n";
  if (run.lidar_gaps > 0) ev << "first_lidar_gap \"" << run.first_lidar_gap << "\"\n";
  ev << "imu_consistency_scans " << run.imu_consistency_scans << "\nmedian_accel_chi2_per_dof "
     << run.median_accel_chi2 << "\nmedian_gyro_chi2_per_dof " << run.median_gyro_chi2 << "\n";
  if (!run.imu_inconsistency.empty()) {
    ev << "imu_inconsistency \"" << run.imu_inconsistency << "\"\n";
  }
  WriteFrameConsistency(run.frames, ev);
  if (run.accel_reference_scans > 0 && run.accel_reference.windows > 0) {
    const FrameConsistency& a = run.accel_reference;
    ev << "accel_reference_scans " << run.accel_reference_scans << "\naccel_reference_windows "
       << a.windows << "\naccel_reference_identity_rms " << a.identity_rms
       << "\naccel_reference_free_rms " << a.free_rms << "\naccel_reference_best_relabelling \""
       << a.best_relabelling << "\"\naccel_reference_best_relabelling_rms "
       << a.best_relabelling_rms << "\n";
  }
  if (!run.accel_relabelling.empty()) {
    ev << "accel_relabelling \"" << run.accel_relabelling << "\"\n";
  }
  if (run.reference_pairs > 0) {
    ev << "reference_disagreement_rms_m " << run.reference_rms_m
       << "\nreference_disagreement_max_m " << run.reference_max_m << "\nreference_path_m "
       << run.reference_path_m << "\nreference_estimate_path_m " << run.reference_estimate_path_m
       << "\nreference_extent_m " << run.reference_extent_m << "\nreference_estimate_extent_m "
       << run.estimate_extent_m << "\n";
  }
  if (!run.reference_ran_off.empty()) {
    ev << "reference_ran_off \"" << run.reference_ran_off << "\"\n";
  }
  if (!run.reference_disagreement.empty()) {
    ev << "reference_disagreement \"" << run.reference_disagreement << "\"\n";
  }
  if (run.overlapping_scans > 0) {
    ev << "overlapping_scans " << run.overlapping_scans << "\nfirst_overlapping_scan \""
       << run.first_overlapping_scan << "\"\n";
  }
  if (!run.extrinsic_disagreement.empty()) {
    ev << "extrinsic_disagreement \"" << run.extrinsic_disagreement << "\"\n";
  }
  // An estimate the lidar never fixed has no ATE; the line says why (run_checks.h).
  if (!run.unregistered_run.empty()) ev << "no_ate \"" << run.unregistered_run << "\"\n";
  if (!run.degenerate_run.empty()) ev << "degenerate_run \"" << run.degenerate_run << "\"\n";
  if (!run.first_input_warning.empty()) {
    ev << "first_input_warning \"" << run.first_input_warning << "\"\n";
  }
  // The reader's recoveries: a run that exits 0 after them says what was recovered from.
  if (!run.input_defects.empty()) ev << "input_defect_kinds " << run.input_defects.size() << "\n";
  for (const std::string& w : run.config_warnings) ev << "config_warning \"" << w << "\"\n";
  for (const io::InputDefect& d : run.input_defects) {
    ev << "input_defect \"" << d.kind << "\" " << d.count << " \"" << d.first << "\"\n";
  }
  if (!run.imu_note.empty()) ev << "imus \"" << run.imu_note << "\"\n";
  for (size_t j = 0; j < run.final_biases.size() && run.true_biases.size() > 1; ++j) {
    ev << "imu" << j << "_bias_estimate";
    for (int k = 0; k < 6; ++k) ev << ' ' << run.final_biases[j][k];
    if (j < run.true_biases.size() && run.true_biases[j]) {
      ev << "\nimu" << j << "_bias_true";
      for (int k = 0; k < 6; ++k) ev << ' ' << (*run.true_biases[j])[k];
    }
    ev << "\n";
  }
  WriteExtrinsicEvaluation(run, ev);
  WriteObservabilitySummary(run, recommended, ev);
  if (!run.nees.empty()) {
    ev << "nees_pose_mean " << Mean(run.nees) << "\nnees_translation_mean "
       << Mean(run.nees_translation) << "\nnees_rotation_mean " << Mean(run.nees_rotation)
       << "\nnees_scans " << run.nees.size() << "\ncoverage_3sigma";
    // Per axis [x y z rx ry rz] of ε: the fraction of the scans inside ±3σ (0.997 if Gaussian
    // and consistent).
    for (const size_t inside : run.nees_inside_3sigma) {
      ev << ' ' << double(inside) / double(run.nees.size());
    }
    ev << "\n";
  }
  if (run.ate) {
    ev << "ate_rmse_m " << run.ate->rmse << "\nate_mean_m " << run.ate->mean << "\nate_max_m "
       << run.ate->max << "\nate_pairs " << run.ate->pairs << "\n";
    // calibration.warmup_replay_s: the live output's ATE, before the replay revised its start.
    ev << "warmup_replayed_scans " << run.warmup_replayed_scans << "\n";
    // Its cost: CPU (its own thread's in the background) and the live output's wait for it.
    ev << "warmup_replay_cpu_ms " << run.warmup_replay_cpu_ms << "\nwarmup_replay_wait_ms "
       << run.warmup_replay_wait_ms << "\nwarmup_replay_scans " << run.warmup_replay_scans << "\n";
    if (run.live_ate) ev << "live_ate_rmse_m " << run.live_ate->rmse << "\n";
    if (!run.dense.empty()) {
      ev << "dense_ate_rmse_m " << EvaluateAte(run.dense, *truth).rmse << "\ndense_poses "
         << run.dense.size() << "\n";
    }
    if (!run.dense_live.empty()) {
      ev << "dense_live_ate_rmse_m " << EvaluateAte(run.dense_live, *truth).rmse << "\n";
    }
    ev << "ate_alignment";
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) ev << ' ' << std::setprecision(17) << run.ate->alignment(r, c);
    }
    ev << std::setprecision(6) << "\n";
  }
}

void WriteTimeOffsetEvaluation(const RunSummary& run, std::ostream& ev) {
  if (const lio::ScanResult* last = LastCalibration(run)) {
    const auto& c = last->calibration;
    for (size_t j = 0; j < c.time_offset_s.size(); ++j) {
      ev << "imu" << j << "_time_offset_s " << std::setprecision(9) << c.time_offset_s[j] << "\nimu"
         << j << "_time_offset_sigma_s "
         << (j < c.time_offset_sigma_s.size() ? c.time_offset_sigma_s[j] : NAN) << "\n";
      if (j < run.true_time_offsets.size() && run.true_time_offsets[j]) {
        ev << "imu" << j << "_time_offset_true_s " << *run.true_time_offsets[j] << "\nimu" << j
           << "_time_offset_error_s " << c.time_offset_s[j] - *run.true_time_offsets[j] << "\n";
      }
    }
    ev << std::setprecision(6);
  }
}

void WriteCalibrationOutputs(const std::string& out, const RunSummary& run,
                             const std::optional<RecommendedCalibration>& recommended,
                             OutputFiles* files, std::ostream& ev) {
  WriteCalibrationLog(out + "/calibration.csv", run);
  files->Add(out + "/calibration.csv", "online calibration estimates and sigmas per scan");
  // After a warm-up replay, the estimates it replaced, which the plot draws beside it.
  if (!run.warmup_live_scans.empty()) {
    WriteCalibrationLog(out + "/calibration_live.csv", run, &run.warmup_live_scans);
    files->Add(out + "/calibration_live.csv", "the estimates the warm-up replay replaced");
  }
  if (recommended) {
    WriteCalibrationYaml(out + "/calibration.yaml", run, *recommended);
    files->Add(out + "/calibration.yaml", "the calibration to use in the next --config");
  }
  if (recommended && !recommended->kept_at_start.empty()) {
    std::string names;
    for (const std::string& n : recommended->kept_at_start) {
      names += " " + n;
    }
    LOG(WARNING) << "Calibration: not informed by the data (sigma near the prior's, or flagged "
                    "unobservable on most scans), written at their start values in "
                 << out << "/calibration.yaml:" << names;
  }
  WriteTimeOffsetEvaluation(run, ev);
}

void PrintRunTables(const std::vector<RunSummary>& runs) {
  std::printf("\n%-12s %8s %8s %8s %13s %6s %6s %10s %9s\n", "method", "ATE[m]", "mean[m]",
              "max[m]", "drift[m/100m]", "scans", "failed", "degenerate", "degen_dir");
  for (const auto& r : runs) {
    if (r.ate) {
      std::printf("%-12s %8.4f %8.4f %8.4f", r.method.c_str(), r.ate->rmse, r.ate->mean,
                  r.ate->max);
    } else {
      std::printf("%-12s %8s %8s %8s", r.method.c_str(), "-", "-", "-");
    }
    char drift[32] = "-";
    if (r.drift_per_100m) std::snprintf(drift, sizeof(drift), "%.3f", *r.drift_per_100m);
    std::printf(" %13s %6zu %6d %10d %9d\n", drift, r.scans.size(), r.failed, r.degenerate,
                r.degenerate_direction_scans);
  }
  std::printf(
      "  degenerate: scans with status `degenerate` (evaluation.txt degenerate_scans):\n"
      "    the lidar did not fix the pose (too few associations, or lidar_only along a\n"
      "    degenerate direction)\n"
      "  degen_dir: scans whose lidar term had a degenerate direction, whatever their\n"
      "    status (with an IMU they stay `ok`; evaluation.txt degenerate_direction_scans,\n"
      "    scans.log degen_dirs)\n");
  std::printf("\nTime per scan [ms] (the first scan, which starts the map, excluded):\n");
  std::printf("%-12s %8s %8s %8s %8s %10s %10s %9s %8s %8s %9s\n", "method", "wall_med", "wall_p95",
              "cpu_med", "cpu_p95", "preprocess", "associate", "solve", "map", "marginal",
              "peak[MB]");
  for (const auto& r : runs) {
    std::printf("%-12s %8.1f %8.1f %8.1f %8.1f %10.1f %10.1f %9.1f %8.1f %8.1f %9.1f\n",
                r.method.c_str(), r.median_ms, r.p95_ms, r.median_cpu_ms, r.p95_cpu_ms,
                r.median_preprocess_ms, r.median_associate_ms, r.median_solve_ms, r.median_map_ms,
                r.median_marginalize_ms, r.peak_rss_kb / 1024.0);
  }
  std::printf(
      "  (preprocess ... marginal: medians of the wall-time split; peak: resident memory)\n");
  for (const auto& r : runs) {
    if (r.imu_rejected + r.points_dropped + r.scans_skipped + r.constant_imu_scans > 0) {
      std::printf(
          "  %-10s input: %d IMU samples rejected, %d points dropped, %d scans skipped, %d scans "
          "with a frozen IMU (first: %s)\n",
          r.method.c_str(), r.imu_rejected, r.points_dropped, r.scans_skipped, r.constant_imu_scans,
          r.first_input_warning.c_str());
    }
  }
  for (const auto& r : runs) {
    if (!r.unregistered_run.empty()) {
      std::printf("  %-10s FAILED, no ATE: %s\n", r.method.c_str(), r.unregistered_run.c_str());
    }
    if (!r.degenerate_run.empty()) {
      std::printf("  %-10s WARNING lidar: %s\n", r.method.c_str(), r.degenerate_run.c_str());
    }
    if (r.lidar_gaps > 0) {
      std::printf("  %-10s lidar: %d gap(s) over 3x the median scan period (first: %s)\n",
                  r.method.c_str(), r.lidar_gaps, r.first_lidar_gap.c_str());
    }
    if (r.overlapping_scans > 0) {
      std::printf("  %-10s WARNING %d scan(s) begin before the previous scan's end (first: %s)\n",
                  r.method.c_str(), r.overlapping_scans, r.first_overlapping_scan.c_str());
    }
    if (!r.imu_inconsistency.empty()) {
      std::printf("  %-10s WARNING imu: %s\n", r.method.c_str(), r.imu_inconsistency.c_str());
    }
    if (!r.frames.warning.empty()) {
      std::printf("  %-10s WARNING frames: %s\n", r.method.c_str(), r.frames.warning.c_str());
    }
    if (!r.accel_relabelling.empty()) {
      std::printf("  %-10s WARNING accelerometer: %s\n", r.method.c_str(),
                  r.accel_relabelling.c_str());
    }
    if (!r.reference_disagreement.empty()) {
      std::printf("  %-10s WARNING reference: %s\n", r.method.c_str(),
                  r.reference_disagreement.c_str());
    }
    if (!r.extrinsic_disagreement.empty()) {
      std::printf("  %-10s WARNING extrinsic: %s\n", r.method.c_str(),
                  r.extrinsic_disagreement.c_str());
    }
    for (const std::string& w : r.config_warnings) {
      std::printf("  %-10s WARNING config: %s\n", r.method.c_str(), w.c_str());
    }
    for (const io::InputDefect& d : r.input_defects) {
      std::printf("  %-10s WARNING input: %zu x %s (first: %s)\n", r.method.c_str(), d.count,
                  d.kind.c_str(), d.first.c_str());
    }
  }
}

}  // namespace ctlio::lioapp
