// Settings that are legal but not physical (docs/user-guide/bad-input.md): a value far beyond
// any real sensor — an accelerometer σ of 10¹⁵ m/s², a bias that walks by metres per second per
// √s — does not stop the odometry, it quietly switches a sensor off (the IMU term weighs nothing,
// the bias absorbs every acceleration) and the run exits 0 with an error several times the usual.
// Validate() cannot refuse them (they are well-formed), so the run warns: in the log, the summary
// and evaluation.txt (`config_warning "..."`). The bounds are 10-100× beyond the noisiest
// consumer MEMS IMU (σ_a ≈ 0.1–1 m/s², σ_g ≈ 0.01–0.1 rad/s, bias walks ≈ 10⁻³–10⁻² per √s), so
// no real setting trips them.
#pragma once

#include <string>
#include <vector>

#include "ctlio/solvers/lio/odometry_config.h"

namespace ctlio::lio {

// One sentence per implausible setting, naming the key, its value, the bound and what it does;
// empty for a plausible config. Keys of methods that do not use them are not checked.
std::vector<std::string> ImplausibleSettings(const OdometryConfig& config);

}  // namespace ctlio::lio
