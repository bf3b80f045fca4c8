// Online lidar–IMU calibration in Singer-LIO and lidar_gyro (top-level YAML section
// `calibration:`): a constant clock offset per IMU and the extrinsic T_imu_lidar as static states
// of the window, each with a Gaussian prior centred on the configured value, kept (with the
// marginal prior's information) when knots leave. Off by default: then no such state exists and
// the estimator is the one without calibration, bit for bit.
//
// Time offset: IMU j's sample stamped t on its own clock measures the state at τ = t + δ_j on the
// lidar clock (the state's time line); δ_j > 0 means the IMU's stamps are late.
#pragma once

#include <cstddef>
#include <vector>

namespace ctlio::lio {

struct CalibrationOptions {
  bool estimate_time_offset = false;
  // δ_j per IMU [s]: initial value and prior mean (empty = 0 for every IMU; otherwise one per IMU).
  // Also applied, unestimated, when estimate_time_offset is off and the list is not all zero.
  std::vector<double> time_offset_s;
  double time_offset_prior_sigma_s = 0.03;  // σ of the prior on δ_j

  bool estimate_extrinsic = false;         // T_imu_lidar (OdometryConfig::T_imu_lidar the mean)
  double extrinsic_prior_sigma_deg = 5.0;  // σ of the prior per rotation axis
  double extrinsic_prior_sigma_m = 0.2;    // σ of the prior per translation axis

  // Observability from the measurements alone (calibration_observability.h): the information on
  // each calibration coordinate (δ_j; the extrinsic's ρ_x … φ_z) from the factors of the newest
  // interval only, summed over the last `observability_horizon_scans` scans and whitened by the
  // prior σ (ν: how many priors' worth of information). Below the kind's threshold the
  // coordinate is reported unobservable and, with `hold_unobservable`, held at its value during
  // the next scan's solve (a prior of whitened information `hold_information` along it), so that
  // it does not drift on the marginal priors' information alone. 0 scans: no check (the
  // behaviour before). While fewer than N scans were assessed the threshold is scaled by their
  // number / N. Thresholds set on the tuning sequences slow/100 and medium/100 (16 beams,
  // every 4th firing, both calibrations from the wrong start, horizon 20), where ν per scan was
  // (slow / medium): δ 0.05 / 40, φ ≤ 8e-5 / ≥ 0.5, ρ ≤ 3e-7 / ≥ 1e-3 — one scan of 0.1 s with
  // its knots free says little about the lever arm even with rotation, so the kinds differ by
  // orders of magnitude; each threshold sits between the two regimes' horizon values
  // (docs/experiments/calibration.md). δ's threshold was 10 until two knots per sweep
  // (knots_per_scan 2, accel_variance 0.16) gave slow/100–101 ν = 28–31 over the horizon with δ
  // 19–25 ms off, where medium/100–103 give ≥ 820 (one knot: ~1 / ~800); 100 sits between both.
  int observability_horizon_scans = 20;
  double time_offset_observability_threshold = 100.0;
  double rotation_observability_threshold = 0.1;
  double translation_observability_threshold = 1e-3;
  // Off by default: on the joint runs (docs/experiments/calibration.md) holding cost ATE in every
  // regime (medium 0.71 vs 0.60 cm, fast 2.14 vs 1.57, slow 29.3 / 10.0 vs 6.9 / 3.5 cm, the
  // wrong start being held), so the check reports and the user decides.
  bool hold_unobservable = false;
  double hold_information = 1e8;  // whitened (σ_hold = σ_prior / 1e4)

  // Warm-up replay: the first `warmup_replay_s` seconds of data (from the first scan's start) are
  // kept, and when a scan ends past that span they are processed again from the start by a fresh
  // pipeline whose start values and prior means are the estimates after that scan (configured
  // σ unchanged; a coordinate the observability check reports unobservable then starts from its
  // configured value, its estimate being drift); that pipeline carries on. Why: with the
  // calibration wrong, the first scans' estimates (a sparse map, the motion's onset) let the
  // calibration states swing (10° and 0.6 m within 0.5 s on the tuning runs) and the map and the
  // marginal priors built on them stay. The scan that triggers it returns with
  // ScanResult::revised_scans > 0 (results() then holds the replayed estimates of the earlier
  // scans; warmup_results() keeps the ones returned live). Costs one processing of the span at that
  // scan (a latency spike) and the memory of its raw scans. 0 = off (no data kept), the default: on
  // the 10 reported sequences (docs/experiments/calibration.md) 2 s brought the medium regime's ATE
  // from 1.8× to 1.3× the true values' and made the fast regime's worse (2.8 vs 2.1 cm), as on the
  // tuning sequences 100–103.
  double warmup_replay_s = 0.0;
  // Passes of the replay: pass p + 1 processes the span again from the estimates pass p ended
  // with (start values and prior means, σ unchanged), and the last pass carries on. Why: the
  // live warm-up's estimates can be farther off than the configured start (the states swing in
  // the first second: 40° and 0.7 m on tuning run fast/100 with two knots per sweep), and a
  // pass started from them swings again; each pass costs one processing of the span.
  int warmup_replay_passes = 1;
  // The last pass holds the calibration coordinates that were observable when it started (all of
  // them with observability_horizon_scans = 0) over the replayed span at the values it starts
  // from (a prior of whitened information hold_information, as hold_unobservable), and releases
  // them with the first scan after it. Why: even started near the truth, the start-up
  // (a sparse one-scan map, the motion's onset) moves the calibration states by several degrees
  // and centimetres, and the map built then stays in use; held, the span is processed as with
  // known values. With one pass it holds the live estimates (worse:
  // docs/experiments/calibration.md).
  bool warmup_replay_hold = false;
  // The last pass runs with the calibration fixed at the values the pass before it ended with
  // (the live estimates with one pass): no calibration states, the estimator of known values,
  // and that pipeline carries on with them for the rest of the run; every later result reports
  // them, with the marginal σ they had, as held. Why: after the span a scan costs what it costs
  // with known values (~30 instead of ~70 ms on the tuning runs), and estimating after the span
  // does not buy ATE (frozen and held after a 4 s span: 1.07 / 1.12x and 1.07 / 1.09x the true
  // values', tuning sequences 100-109, medium / fast); but the final values are the span's (12 s:
  // the lever arm within 1.00 cm, where held-then-estimated reaches 0.57 cm).
  // docs/experiments/calibration.md, "A longer warm-up". Exclusive with warmup_replay_hold.
  bool warmup_replay_freeze = false;
  // Warm-up forgetting, the replay's alternative at no reprocessing: after the first estimated
  // scan that ends `warmup_forget_s` or more seconds after the first scan began, the window's
  // marginal priors forget what they say about the calibration states and the gravity direction
  // refined with them (SlidingWindow::ForgetInformation: their Schur complement over those
  // states; the knots keep their marginal, the configured prior on the calibration stays). Why:
  // the warm-up's scans were marginalised while the calibration was far off, and that
  // information stays linearised there; forgotten, the calibration is estimated from the scans
  // after the span, linearised near its estimate. Measured on the tuning runs (60 s, 12 s span):
  // the clock offset settles as with the replay and a calibrating scan costs 1.1-1.3x the run
  // without calibration, but the extrinsic is worse than the replay's (the lever arm 0.7-2 cm off
  // in medium and fast motion, where the replay writes it within 0.63 cm), so data/calibration.yaml
  // keeps the replay (docs/experiments/calibration.md, "Forgetting the warm-up instead of
  // replaying it"). 0 = off (the default); exclusive with warmup_replay_s.
  double warmup_forget_s = 0.0;
  // With warmup_forget_s: the voxel map is restarted from the forgetting scan's points, since the
  // map of the span was built with the calibration far off and full voxels keep their first
  // points (tuning runs fast/100-102: the lever arm written 2.16 / 1.12 / 4.90 cm off without,
  // 0.99 / 0.75 / 1.51 cm with it; docs/experiments/calibration.md).
  bool warmup_forget_restart_map = false;
  // What a run writes as the calibration to use (calibration.yaml, RecommendCalibration in
  // apps/lio/calibration_output.h): per coordinate the last estimate when its marginal σ is below
  // the threshold of its kind, else the start value (the data did not inform it). The targets of
  // issue 45 (0.5 ms, 0.1°, 1 cm); the share of scans the observability check flagged does not
  // enter (a 20.045 ± 0.20 ms offset flagged on 81% of the scans is a calibration).
  double write_max_sigma_s = 5e-4;   // time offset δ_j [s]
  double write_max_sigma_deg = 0.1;  // extrinsic rotation φ per axis [deg]
  double write_max_sigma_m = 0.01;   // extrinsic translation ρ per axis [m]
  // Above its threshold, an estimate is still written when the data informed it: its σ is at
  // most `write_max_sigma_ratio` of its prior σ (0.1: ≥ 99 priors' worth of information, since
  // information ∝ 1/σ²) and the observability check flagged it after at most
  // `write_max_unobservable_fraction` of the assessed scans. Why the second condition: in
  // translation-only motion the window's σ of a drifting coordinate is small as well (δ 1.1 ms
  // of a 30 ms prior while 12 ms off: the marginal prior's information counted again each
  // slide), and the check flags it after 90–100% of the scans, where gentle motion's informed
  // axes (σ 0.11–0.23° of a 5° prior, within 0.05°) are flagged after 0%.
  // docs/experiments/calibration.md, "The write rule".
  double write_max_sigma_ratio = 0.1;
  double write_max_unobservable_fraction = 0.5;
  // Either way, an estimate that moved by more than `write_max_drift_sigmas` × its final σ over
  // the second half of the run's scans with nothing held is not written (the start is kept): an
  // honest converging estimate moves by at most about σ there, a drifting one steadily. Why: the
  // window's σ of a drifting coordinate need not be large, nor the check's share: on tuning run
  // slow/101 δ ended 11 ms off with σ 0.44 ms (below 0.5 ms) and was flagged after 2% of the
  // scans; it moved 7.4σ over the second half, slow/100's 3.0σ (φ up to 5.4σ), where every
  // coordinate of walking/medium/fast 100–101 moved ≤ 0.3σ. 0: no drift check.
  // docs/experiments/calibration.md, "The write rule".
  double write_max_drift_sigmas = 2.5;

  // Set by the held pass of a warm-up replay, not read from YAML: C_mi stays held (as with
  // window.estimate_gravity false and no extrinsic estimated) although the extrinsic is
  // estimated, its first scan being placed with start values the warm-up produced.
  bool hold_gravity = false;

  // δ_j's configured value (0 when the list is empty).
  double TimeOffset(int j) const {
    return time_offset_s.empty() ? 0.0 : time_offset_s[static_cast<std::size_t>(j)];
  }
  bool any() const { return estimate_time_offset || estimate_extrinsic; }
  // The prior σ per calibration coordinate in the window's order: δ_j for j < num_time_offsets
  // [s], then with the extrinsic ρ_xyz [m] and φ_xyz [rad].
  std::vector<double> PriorSigmas(int num_time_offsets, bool extrinsic) const;
  bool replays_warmup() const { return any() && warmup_replay_s > 0.0; }
  bool forgets_warmup() const { return any() && warmup_forget_s > 0.0; }

  void Validate() const;  // throws std::invalid_argument naming the field
};

}  // namespace ctlio::lio
