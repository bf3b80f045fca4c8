#include "run_odometry.h"

#include <glog/logging.h>
#include <sys/resource.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "accel_reference.h"
#include "ctlio/eval/trajectory_metrics.h"
#include "ctlio/factors/imu/saturating_ns.h"
#include "ctlio/io/checked_output.h"
#include "ctlio/io/warning_limiter.h"
#include "ctlio/solvers/lio/calibrating_odometry.h"
#include "ctlio/solvers/lio/config_plausibility.h"
#include "ctlio/solvers/lio/lio_odometry.h"
#include "extrinsic_agreement.h"
#include "frame_consistency.h"
#include "run_checks.h"

namespace ctlio::lioapp {

// Process-wide high-water mark of the resident set (getrusage ru_maxrss, kB on Linux).
long PeakRssKb() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return usage.ru_maxrss;
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double idx = p * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(idx));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (idx - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

void ImusFromSource(const io::DataSource& source, lio::OdometryConfig* config) {
  const std::vector<io::ImuInfo> imus = source.Imus();
  if (!config->imus.empty() || imus.empty()) return;
  if (imus.size() == 1 && imus[0].T_body_imu.Matrix().isIdentity(0.0)) return;
  for (const io::ImuInfo& info : imus) {
    lio::OdometryConfig::ImuSensor sensor;
    sensor.T_robot_imu = info.T_body_imu;
    const auto ratio2 = [](double s, double s0) {
      return s > 0 && s0 > 0 ? s * s / (s0 * s0) : 1.0;
    };
    sensor.accel_variance = config->accel_variance * ratio2(info.accel_sigma, imus[0].accel_sigma);
    sensor.gyro_variance = config->gyro_variance * ratio2(info.gyro_sigma, imus[0].gyro_sigma);
    config->imus.push_back(sensor);
  }
}

double Mean(const std::vector<double>& v) {
  if (v.empty()) return NAN;
  double sum = 0.0;
  for (const double x : v) sum += x;
  return sum / double(v.size());
}

namespace {

// T_world_lidar of a scan: T_mr with the extrinsic estimated at that scan when it is estimated,
// else the run's.
SE3 LidarPose(const lio::ScanResult& r, const SE3& T_imu_lidar) {
  return r.T_mr * (r.calibration.has_extrinsic ? r.calibration.T_imu_lidar : T_imu_lidar);
}

// One scan's result into the summary: the counts by status, the trajectory (the lidar pose with
// the extrinsic estimated at that scan, when it is estimated), biases and extrinsic, the log.
// `index` counts the scans from 0: a failure of the first (initialisation) is not a failed scan.
void Tally(const lio::ScanResult& r, size_t index, const SE3& T_imu_lidar, RunSummary* run) {
  if (r.status == lio::ScanStatus::kSuspect) ++run->constant_imu_scans;
  switch (r.status) {
    case lio::ScanStatus::kFailed:
      if (index > 0) {
        ++run->failed;
        if (run->first_failure.empty()) run->first_failure = r.message;
      }
      break;
    case lio::ScanStatus::kDegenerate:
      ++run->degenerate;
      break;
    case lio::ScanStatus::kImuGap:
      ++run->imu_gaps;
      break;
    default:
      break;
  }
  if (r.degeneracy.num_degenerate() > 0) ++run->degenerate_direction_scans;
  if (r.status != lio::ScanStatus::kFailed) {
    if (!r.imu_biases.empty()) run->final_biases = r.imu_biases;
    if (r.calibration.has_extrinsic) {
      run->extrinsic_estimated = true;
      run->final_extrinsic = r.calibration.T_imu_lidar;
      run->final_extrinsic_sigma = r.calibration.extrinsic_sigma;
    }
    run->trajectory.push_back({r.t_ns, LidarPose(r, T_imu_lidar)});
  }
  run->scans.push_back(r);
}

// Undoes every Tally (and the dense samples taken with them).
void ResetTally(RunSummary* run) {
  run->constant_imu_scans = run->failed = run->degenerate = run->imu_gaps = 0;
  run->degenerate_direction_scans = 0;
  run->first_failure.clear();
  run->final_biases.clear();
  run->trajectory.clear();
  run->dense.clear();
  run->dense_live.clear();
  run->scans.clear();
}

}  // namespace

lio::LidarScan TakeLidarScan(io::ScanFrame* frame) {
  lio::LidarScan scan;
  scan.begin_ns = frame->start_ns;
  scan.end_ns = frame->end_ns;
  scan.points = std::move(frame->cloud.points);
  scan.times_ns = std::move(frame->cloud.times_ns);
  if (scan.times_ns.empty()) scan.times_ns.assign(scan.points.size(), scan.end_ns);
  return scan;
}

namespace {
// The config's extrinsic against the data's own, when the data have one (a source without one
// throws from ImuFromLidar: nothing to compare). Warned about here; the caller reports it.
std::string CompareWithDataExtrinsic(io::DataSource& source, const SE3& config_T) {
  std::string origin;
  SE3 data_T;
  try {
    data_T = source.ImuFromLidar();
    origin = source.ExtrinsicOrigin();
  } catch (const std::exception&) {
    return "";
  }
  const std::string d = ExtrinsicDisagreement(config_T, "config", data_T, origin);
  if (!d.empty()) {
    LOG(WARNING) << source.Name() << ": the config's extrinsic is used, but it disagrees with the "
                 << "data's: " << d;
  }
  return d;
}
}  // namespace

RunSummary RunOdometry(io::DataSource& source, lio::OdometryConfig config,
                       const RunOptions& options, double failure_ate) {
  RunSummary run;
  ImusFromSource(source, &config);
  const int num_imus = config.num_imus();
  if (num_imus > 1) {
    std::ostringstream note;
    if (config.method == lio::LioMethod::kImuInput) {
      note << "imu_input preintegrates one IMU, IMU " << config.input_imu << " (imu.input_imu), of "
           << num_imus << "; the others are not used (IMU-as-input fuses one IMU: a second one "
           << "would need its own preintegration and, at a lever arm, the derivative of the gyro)";
    } else if (config.method == lio::LioMethod::kLidarOnly) {
      note << "lidar_only uses none of the " << num_imus << " IMUs";
    } else {
      note << lio::LioMethodName(config.method) << " takes every sample of all " << num_imus
           << " IMUs as measurements, each IMU with its mounting and its own biases";
    }
    run.imu_note = note.str();
    LOG(WARNING) << source.Name() << ": " << lio::LioMethodName(config.method) << ": "
                 << run.imu_note;
  }
  if (options.extrinsic_from_config) {
    run.extrinsic_origin = "the config (extrinsic:)";
    run.extrinsic_disagreement = CompareWithDataExtrinsic(source, config.T_imu_lidar);
  } else {
    config.T_imu_lidar = source.ImuFromLidar();
    run.extrinsic_origin = source.ExtrinsicOrigin();
  }
  {
    const Eigen::AngleAxisd r(config.T_imu_lidar.rotation());
    LOG(INFO) << "T_imu_lidar from " << run.extrinsic_origin << ": translation ["
              << config.T_imu_lidar.translation().transpose() << "] m, rotation "
              << r.angle() * 180.0 / M_PI << " deg about [" << r.axis().transpose() << "]";
  }
  if (const auto g = source.Gravity()) config.gravity = *g;
  // The odometry applies the input gates (config.input); the runner only reports them.
  auto odometry = std::make_unique<lio::CalibratingOdometry>(
      config, lio::ReplaySchedule{options.replay_adopt_after_s >= 0.0,
                                  std::max(0.0, options.replay_adopt_after_s)});
  odometry->SampleFinalTrajectory(options.trajectory_rate_hz);
  // T_mr first; T_imu_lidar at the end (below).
  const auto take_final = [&](const std::vector<std::pair<int64_t, SE3>>& samples) {
    for (const auto& [t, T_mr] : samples) run.dense.push_back({t, T_mr});
  };
  // A recovery of the runner or of the odometry's input gates (a scan skipped, IMU samples
  // rejected, points dropped) is an error in strict mode, as the readers' recoveries are.
  auto recovered = [&](const std::string& m) {
    if (io::WarningLimiter::Strict()) {
      throw std::runtime_error(source.Name() + ": " + m +
                               " (--strict: a defect that would be recovered is an "
                               "error; run without it to recover and log)");
    }
  };
  auto warn = [&](const std::string& m) {
    LOG(WARNING) << source.Name() << ": " << m;
    if (run.first_input_warning.empty()) run.first_input_warning = m;
  };
  bool have_previous = false;
  int64_t previous_end = 0;
  run.method = lio::LioMethodName(config.method);
  run.config_warnings = lio::ImplausibleSettings(config);
  for (const std::string& w : run.config_warnings) LOG(WARNING) << run.method << ": config: " << w;
  run.source = source.Name();
  const SE3 T_imu_lidar = config.T_imu_lidar;
  run.initial_extrinsic = run.final_extrinsic = T_imu_lidar;
  run.initial_time_offsets = config.calibration.time_offset_s;
  run.true_extrinsic = source.TrueImuFromLidar();
  const size_t total = options.max_scans > 0
                           ? (source.NumScans() > 0 ? std::min(options.max_scans, source.NumScans())
                                                    : options.max_scans)
                           : source.NumScans();
  io::ScanFrame frame;
  std::vector<double> ms;
  SE3 live_from_replay;  // identity until a calibration warm-up replay
  // The calibration warm-up replay replaced the earlier scans' results: tally those instead
  // (their live dense samples are gone with the pipeline that made them: the scan poses stand
  // in; the final ones are the replay's, taken after).
  const auto revise = [&](const lio::ScanResult& r) {
    const std::deque<lio::ScanResult>& all = odometry->results();
    ResetTally(&run);
    for (size_t i = 0; i + 1 < all.size(); ++i) {
      Tally(all[i], i, T_imu_lidar, &run);
      if (all[i].status != lio::ScanStatus::kFailed && options.trajectory_rate_hz > 0.0) {
        run.dense_live.push_back(run.trajectory.back());
      }
    }
    run.warmup_replayed_scans = r.revised_scans;
    run.warmup_live_scans.assign(odometry->warmup_results().begin(),
                                 odometry->warmup_results().end());
    if (const auto& cost = odometry->last_replay()) {
      run.warmup_replay_cpu_ms = cost->cpu_ms;
      run.warmup_replay_wait_ms = cost->wait_ms;
      run.warmup_replay_scans = cost->scans;
    }
  };
  size_t done = 0;
  std::vector<int64_t> scan_ends;  // of the scans handed to the odometry, for the lidar gaps
  std::optional<std::pair<std::chrono::steady_clock::time_point, int64_t>> pace_origin;
  // The IMU's frame against the lidar trajectory's (frame_consistency.h); lidar_only uses no IMU.
  FrameConsistencyCheck frames = ImuFrameCheck(config);
  const bool check_frames = config.method != lio::LioMethod::kLidarOnly;
  // lidar_gyro's own poses already leave the accelerometer out: its frame fit is the reference.
  std::optional<AccelReference> reference;
  if (options.accel_reference_scans > 0 && options.accel_reference_config &&
      (config.method == lio::LioMethod::kSingerLio || config.method == lio::LioMethod::kImuInput)) {
    lio::OdometryConfig c = *options.accel_reference_config;
    c.T_imu_lidar = config.T_imu_lidar;
    c.gravity = config.gravity;
    c.imus = config.imus;
    reference.emplace(c, options.accel_reference_scans);
  }
  while ((options.max_scans == 0 || done < options.max_scans) && source.Next(&frame)) {
    for (const io::ImuSample& x : frame.imu) {
      odometry->AddImu(x);
      if (check_frames) frames.AddImu(x);
      if (reference) reference->AddImu(x);
    }
    if (have_previous && frame.end_ns <= previous_end) {
      ++run.scans_skipped;
      recovered("scan " + std::to_string(frame.index) + " would be skipped: its end " +
                io::FormatSecondsNs(frame.end_ns) + " s is not after the previous scan's " +
                io::FormatSecondsNs(previous_end) + " s");
      warn("scan " + std::to_string(frame.index) + " skipped: its end " +
           io::FormatSecondsNs(frame.end_ns) + " s is not after the previous scan's " +
           io::FormatSecondsNs(previous_end) + " s");
      continue;
    }
    if (have_previous && frame.start_ns < previous_end &&
        SaturatingSubNs(previous_end, frame.start_ns) >
            SaturatingSubNs(frame.end_ns, frame.start_ns) / 10) {
      const std::string m =
          "scan " + std::to_string(frame.index) + ": its interval [" +
          io::FormatSecondsNs(frame.start_ns) + ", " + io::FormatSecondsNs(frame.end_ns) +
          "] s begins " +
          std::to_string(1e-9 * double(SaturatingSubNs(previous_end, frame.start_ns))) +
          " s before the previous scan's end " + io::FormatSecondsNs(previous_end) +
          " s: scan intervals overlap (wrong scan start/end times?)";
      if (run.overlapping_scans++ < 5) warn(m);
      if (run.first_overlapping_scan.empty()) run.first_overlapping_scan = m;
    }
    if (options.play_rate > 0.0) {
      if (!pace_origin) pace_origin.emplace(std::chrono::steady_clock::now(), frame.end_ns);
      const double seconds = 1e-9 * double(frame.end_ns - pace_origin->second) / options.play_rate;
      std::this_thread::sleep_until(pace_origin->first +
                                    std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                        std::chrono::duration<double>(seconds)));
    }
    const lio::LidarScan scan = TakeLidarScan(&frame);
    const lio::ScanResult r = odometry->AddScan(scan);
    if (reference) {
      reference->AddScan(scan);
      if (r.status == lio::ScanStatus::kOk) reference->AddEstimate(r.t_ns, r.T_mr);
    }
    if (r.status == lio::ScanStatus::kOk && check_frames) {
      frames.AddPose(r.t_ns, r.T_mr);
    } else {
      frames.Break();
    }
    run.imu_rejected += r.imu_rejected;
    run.points_dropped += r.points_dropped;
    if (r.imu_rejected > 0 || r.points_dropped > 0) {
      recovered("scan " + std::to_string(frame.index) + ": " + r.message);
    }
    if (r.imu_rejected > 0 || r.points_dropped > 0 || r.status == lio::ScanStatus::kSuspect) {
      warn("scan " + std::to_string(frame.index) + ": " + r.message);
    }
    have_previous = true;
    previous_end = frame.end_ns;
    scan_ends.push_back(frame.end_ns);
    ++done;
    ms.push_back(r.milliseconds);
    if (r.revised_scans > 0) {
      // The replay's map frame is its first scan placed with the warm-up's extrinsic, not the
      // live one's: the live output continues in the live frame through the trigger scan's two
      // estimates of the same lidar pose.
      const lio::ScanResult& live = odometry->warmup_results().back();
      if (live.status != lio::ScanStatus::kFailed && r.status != lio::ScanStatus::kFailed) {
        live_from_replay = LidarPose(live, T_imu_lidar) * LidarPose(r, T_imu_lidar).Inverse();
      }
    }
    if (r.status != lio::ScanStatus::kFailed) {
      run.live_trajectory.push_back({r.t_ns, live_from_replay * LidarPose(r, T_imu_lidar)});
      const std::vector<Vec3>* inserted = odometry->newest_map_points();
      if (options.map_points && inserted != nullptr) {
        options.map_points(r, *inserted);
      }
    }
    if (r.revised_scans > 0) revise(r);
    Tally(r, done - 1, T_imu_lidar, &run);
    if (r.status != lio::ScanStatus::kFailed && options.trajectory_rate_hz > 0.0) {
      const SE3& T_rl = r.calibration.has_extrinsic ? r.calibration.T_imu_lidar : T_imu_lidar;
      auto samples = odometry->SampleNewestInterval(options.trajectory_rate_hz);
      if (samples.empty()) samples.emplace_back(r.t_ns, r.T_mr);  // the first state
      for (const auto& [t, T_mr] : samples) run.dense_live.push_back({t, T_mr * T_rl});
    }
    take_final(odometry->TakeFinalTrajectory());
    if (options.progress) options.progress(done, total, r);
  }
  if (const auto r = odometry->Finish()) {
    // A background warm-up replay not adopted before the input ended: its estimates, not a live
    // output (no latency, no live pose).
    revise(*r);
    Tally(*r, done - 1, T_imu_lidar, &run);
    take_final(odometry->TakeFinalTrajectory());
  }
  take_final(odometry->FinalTrajectoryTail());  // the window's estimates are final now
  // The extrinsic is one static state: its final estimate for every pose (each scan's own
  // estimate would put its changes into the trajectory as jumps).
  for (io::StampedPose& p : run.dense) p.pose = p.pose * run.final_extrinsic;
  // The first scan (map creation) is not a registration: keep it out of the latency figures.
  std::vector<double> reg(ms.begin() + std::min<size_t>(1, ms.size()), ms.end());
  run.median_ms = Percentile(reg, 0.5);
  run.p95_ms = Percentile(reg, 0.95);
  run.max_ms = reg.empty() ? 0.0 : *std::max_element(reg.begin(), reg.end());
  {
    std::vector<double> cpu, pre, assoc, solve, map, marg;
    for (size_t i = 1; i < run.scans.size(); ++i) {
      const lio::ScanResult& r = run.scans[i];
      cpu.push_back(r.cpu_ms);
      pre.push_back(r.ms_preprocess);
      assoc.push_back(r.ms_associate);
      solve.push_back(r.ms_solve);
      map.push_back(r.ms_map);
      marg.push_back(r.ms_marginalize);
    }
    run.median_cpu_ms = Percentile(cpu, 0.5);
    run.p95_cpu_ms = Percentile(cpu, 0.95);
    run.median_preprocess_ms = Percentile(pre, 0.5);
    run.median_associate_ms = Percentile(assoc, 0.5);
    run.median_solve_ms = Percentile(solve, 0.5);
    run.median_map_ms = Percentile(map, 0.5);
    run.median_marginalize_ms = Percentile(marg, 0.5);
  }
  run.peak_rss_kb = PeakRssKb();
  if (const auto truth = source.GroundTruth()) {
    // No ATE where there is no estimate to evaluate (e.g. every scan failed initialisation).
    const AteResult ate = EvaluateAte(run.trajectory, *truth);
    if (ate.pairs >= 3) run.ate = ate;
    const AteResult live = EvaluateAte(run.live_trajectory, *truth);
    if (live.pairs >= 3) run.live_ate = live;
    run.drift_per_100m = DriftPer100m(run.trajectory, *truth);
    if (config.pose_covariance) {
      PoseNees n = EvaluatePoseNees(run.scans, *truth, T_imu_lidar);
      run.nees = std::move(n.pose);
      run.nees_translation = std::move(n.translation);
      run.nees_rotation = std::move(n.rotation);
      run.nees_inside_3sigma = n.inside_3sigma;
    }
  }
  for (const io::ImuInfo& info : source.Imus()) {
    run.true_biases.push_back(info.true_bias);
    run.true_time_offsets.push_back(info.true_time_offset_s);
  }
  // Whole-run checks (run_checks.h): no ATE of an estimate the lidar never fixed.
  run.unregistered_run = UnregisteredRunReason(run.scans);
  if (!run.unregistered_run.empty()) {
    LOG(WARNING) << source.Name() << ": " << run.method << ": " << run.unregistered_run;
    run.ate.reset();
    run.live_ate.reset();
    run.drift_per_100m.reset();
  }
  run.degenerate_run = DegenerateRunWarning(run.scans);
  if (!run.degenerate_run.empty()) {
    LOG(WARNING) << source.Name() << ": " << run.method << ": " << run.degenerate_run;
  }
  run.input_defects = source.InputDefects();
  const LidarGaps gaps = FindLidarGaps(scan_ends);
  run.lidar_gaps = gaps.count;
  run.first_lidar_gap = gaps.first;
  if (gaps.count > 0) {
    LOG(WARNING) << source.Name() << ": " << gaps.count << " lidar gap(s) (scans missing: a "
                 << "spacing over 3x the median scan period), longest " << gaps.longest_s
                 << " s; first: " << gaps.first;
  }
  const ImuConsistency imu = CheckImuConsistency(run.scans, config);
  run.imu_consistency_scans = imu.moving_scans;
  run.median_accel_chi2 = imu.median_accel;
  run.median_gyro_chi2 = imu.median_gyro;
  run.imu_inconsistency = imu.warning;
  if (!imu.warning.empty()) {
    LOG(WARNING) << source.Name() << ": " << run.method << ": " << imu.warning;
  }
  if (check_frames) {
    run.frames = frames.Result();
    // A calibrating run starts from the nominal extrinsic and clock offset the check judges: what
    // it finds is what the run calibrates, reported beside calibration.yaml, not an input error.
    const bool calibrating = config.calibration.any();
    if (!run.frames.warning.empty() && calibrating) {
      run.frames.warning +=
          "; this run calibrates the extrinsic / clock offset from those start values: its "
          "estimate is in calibration.yaml (not an error under --strict)";
    }
    if (!run.frames.warning.empty()) {
      LOG(WARNING) << source.Name() << ": " << run.method << ": " << run.frames.warning;
      if (io::WarningLimiter::Strict() && !calibrating) {
        throw std::runtime_error(source.Name() + ": " + run.method + ": " + run.frames.warning +
                                 " (--strict / input.strict: an inconsistent input is an error)");
      }
    }
  }
  const ReferenceDisagreement d = reference ? reference->Disagreement() : ReferenceDisagreement();
  run.reference_ran_off = ReferenceRanOff(d);
  if (reference || config.method == lio::LioMethod::kLidarGyro) {
    run.accel_reference = reference ? reference->Result() : run.frames;
    run.accel_reference_scans = reference ? reference->scans() : static_cast<int>(done);
    if (run.reference_ran_off.empty()) {
      run.accel_relabelling = RelabellingWarning(run.accel_reference, run.accel_reference_scans);
    }
    if (!run.accel_relabelling.empty()) {
      LOG(WARNING) << source.Name() << ": " << run.method << ": " << run.accel_relabelling;
      if (io::WarningLimiter::Strict()) {
        throw std::runtime_error(source.Name() + ": " + run.method + ": " + run.accel_relabelling +
                                 " (--strict / input.strict: an inconsistent input is an error)");
      }
    }
  }
  if (reference) {
    run.reference_rms_m = d.rms_m;
    run.reference_max_m = d.max_m;
    run.reference_path_m = d.path_m;
    run.reference_estimate_path_m = d.estimate_path_m;
    run.reference_extent_m = d.extent_m;
    run.estimate_extent_m = d.estimate_extent_m;
    run.reference_pairs = d.pairs;
    if (run.reference_ran_off.empty()) {
      run.reference_disagreement = DisagreementWarning(d, run.accel_reference_scans);
    }
    if (!run.reference_disagreement.empty()) {
      LOG(WARNING) << source.Name() << ": " << run.method << ": " << run.reference_disagreement;
    }
  }
  run.failure = run.failed > 0 || run.constant_imu_scans > 0 ||
                (run.ate && !(run.ate->rmse <= failure_ate)) || run.trajectory.size() < 2 ||
                !run.unregistered_run.empty();
  return run;
}

}  // namespace ctlio::lioapp
