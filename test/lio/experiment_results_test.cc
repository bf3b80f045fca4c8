// What ctlio_experiment writes besides the runs (apps/lio/experiment_results.h): the bar labels
// of table2.svg keep two significant digits of the RMSE ATE in centimetres.
#include "lio/experiment_results.h"

#include <gtest/gtest.h>

namespace ctlio::lioapp {
namespace {

TEST(ExperimentResults, BarLabelsKeepTwoSignificantDigitsInCentimetres) {
  // Singer-LIO and the baseline in the slow regime of Table II: one decimal made both "0.3".
  EXPECT_EQ(CentimetreLabel(0.0026), "0.26");
  EXPECT_EQ(CentimetreLabel(0.0034), "0.34");
  EXPECT_EQ(CentimetreLabel(0.00697), "0.7");  // a trailing zero is not printed
  EXPECT_EQ(CentimetreLabel(0.0127), "1.3");
  EXPECT_EQ(CentimetreLabel(0.1234), "12");
  EXPECT_EQ(CentimetreLabel(0.000543), "0.054");
}

}  // namespace
}  // namespace ctlio::lioapp
