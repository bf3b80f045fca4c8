// The calibration options' checks (the config parsers and the YAML fuzz target link this alone).
#include "ctlio/solvers/lio/calibration_options.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace ctlio::lio {

void CalibrationOptions::Validate() const {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("OdometryConfig: ") + what);
  };
  for (double d : time_offset_s) {
    // A clock offset beyond a second is a wrong stamp base, not something to estimate.
    require(std::isfinite(d) && std::abs(d) <= 1.0,
            "calibration.time_offset_s must be in [-1, 1] s");
  }
  require(std::isfinite(time_offset_prior_sigma_s) && time_offset_prior_sigma_s > 0,
          "calibration.time_offset_prior_sigma_s must be positive");
  require(std::isfinite(extrinsic_prior_sigma_deg) && extrinsic_prior_sigma_deg > 0,
          "calibration.extrinsic_prior_sigma_deg must be positive");
  require(std::isfinite(extrinsic_prior_sigma_m) && extrinsic_prior_sigma_m > 0,
          "calibration.extrinsic_prior_sigma_m must be positive");
  require(observability_horizon_scans >= 0,
          "calibration.observability_horizon_scans must be >= 0 (0: no check)");
  for (double t : {time_offset_observability_threshold, rotation_observability_threshold,
                   translation_observability_threshold}) {
    require(std::isfinite(t) && t >= 0,
            "calibration.*_observability_threshold must be finite and >= 0");
  }
  require(std::isfinite(hold_information) && hold_information > 0,
          "calibration.hold_information must be positive");
  // Beyond a minute the kept raw scans (≈ 7 MB per full-resolution 128-beam sweep) dominate.
  require(std::isfinite(warmup_replay_s) && warmup_replay_s >= 0 && warmup_replay_s <= 60,
          "calibration.warmup_replay_s must be in [0, 60] s (0: no replay)");
  require(std::isfinite(warmup_forget_s) && warmup_forget_s >= 0 && warmup_forget_s <= 3600,
          "calibration.warmup_forget_s must be in [0, 3600] s (0: off)");
  require(warmup_forget_s > 0 || !warmup_forget_restart_map,
          "calibration.warmup_forget_restart_map needs warmup_forget_s > 0");
  require(!(warmup_forget_s > 0 && warmup_replay_s > 0),
          "calibration.warmup_forget_s and warmup_replay_s: choose one (forgetting replaces the "
          "replay)");
  require(warmup_replay_passes >= 1 && warmup_replay_passes <= 10,
          "calibration.warmup_replay_passes must be in [1, 10]");
  // Without a replay span they would do nothing: say so rather than run without them.
  require(warmup_replay_s > 0 ||
              (warmup_replay_passes == 1 && !warmup_replay_hold && !warmup_replay_freeze),
          "calibration.warmup_replay_passes / warmup_replay_hold / warmup_replay_freeze need "
          "warmup_replay_s > 0");
  for (double t : {write_max_sigma_s, write_max_sigma_deg, write_max_sigma_m}) {
    require(std::isfinite(t) && t > 0, "calibration.write_max_sigma_* must be finite and > 0");
  }
  // 0 turns the ratio off (the thresholds alone); 1 would call an estimate no better than its
  // prior informed.
  require(std::isfinite(write_max_sigma_ratio) && write_max_sigma_ratio >= 0 &&
              write_max_sigma_ratio < 1,
          "calibration.write_max_sigma_ratio must be in [0, 1) (0: the thresholds alone)");
  require(std::isfinite(write_max_unobservable_fraction) && write_max_unobservable_fraction >= 0 &&
              write_max_unobservable_fraction <= 1,
          "calibration.write_max_unobservable_fraction must be in [0, 1]");
  require(std::isfinite(write_max_drift_sigmas) && write_max_drift_sigmas >= 0,
          "calibration.write_max_drift_sigmas must be finite and >= 0 (0: no drift check)");
  require(!(warmup_replay_hold && warmup_replay_freeze),
          "calibration.warmup_replay_hold and warmup_replay_freeze: choose one for the last pass");
}

std::vector<double> CalibrationOptions::PriorSigmas(int num_time_offsets, bool extrinsic) const {
  std::vector<double> sigma(static_cast<std::size_t>(num_time_offsets), time_offset_prior_sigma_s);
  if (extrinsic) {
    sigma.insert(sigma.end(), 3, extrinsic_prior_sigma_m);
    sigma.insert(sigma.end(), 3, extrinsic_prior_sigma_deg * M_PI / 180.0);
  }
  return sigma;
}

}  // namespace ctlio::lio
