// TEMPORARY stub while the GP factors land.
#include "ctlio/solvers/lio/singer_lio.h"

#include <stdexcept>
namespace ctlio::lio {
struct SingerLio::Impl {};
SingerLio::SingerLio(const OdometryConfig& config) : LioOdometry(config) {}
SingerLio::~SingerLio() = default;
void SingerLio::Initialise(const PreparedScan&, ScanResult*) { throw std::runtime_error("todo"); }
void SingerLio::Process(const PreparedScan&, ScanResult*) { throw std::runtime_error("todo"); }
}  // namespace ctlio::lio
