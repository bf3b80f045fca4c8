// ctlio_evaluate: ATE and RPE of an estimated trajectory against a reference (SPEC §6).
//
//   ctlio_evaluate --estimate=est.txt --reference=gt.txt [--align=se3|sim3|none]
//                  [--tolerance=0.01] [--rpe_distances=10,50] [--rpe_times=1,10]
//                  [--output_dir=eval_out] [--plot=true]
// Both files are TUM ("t x y z qx qy qz qw") or KITTI (12 numbers; times from
// --estimate_times / --reference_times, else index·0.1 s). Writes metrics.txt, metrics.json,
// errors.csv and, if python3 with matplotlib is found, top_view.png and error_over_time.png.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "common/command_line.h"
#include "ctlio/eval/trajectory_metrics.h"
#include "ctlio/io/checked_output.h"
#include "ctlio/io/trajectory_io.h"

#ifndef CTLIO_TOOLS_DIR
#define CTLIO_TOOLS_DIR "tools"
#endif

DEFINE_string(estimate, "", "Estimated trajectory (TUM or KITTI)");
DEFINE_string(reference, "", "Reference trajectory (TUM or KITTI)");
DEFINE_string(estimate_times, "", "Times file for a KITTI-format estimate");
DEFINE_string(reference_times, "", "Times file for a KITTI-format reference");
DEFINE_string(align, "se3", "Alignment before ATE: se3 | sim3 | none");
DEFINE_double(tolerance, 0.01, "Timestamp association tolerance [s]");
DEFINE_string(rpe_distances, "10", "RPE distance windows [m], comma separated (empty = none)");
DEFINE_string(rpe_times, "1", "RPE time windows [s], comma separated (empty = none)");
DEFINE_string(output_dir, "", "Folder for metrics.txt/json, errors.csv and plots (empty = none)");
DEFINE_bool(plot, true, "Write PNG plots with tools/plot_trajectory_error.py");
DEFINE_string(plot_script, CTLIO_TOOLS_DIR "/plot_trajectory_error.py", "Plot script");
DEFINE_string(python, "",
              "Python interpreter (default: first of python3, /usr/bin/python3 "
              "that has matplotlib)");

namespace {

std::vector<double> ParseList(const std::string& s) {
  std::vector<double> out;
  std::stringstream ss(s);
  std::string tok;
  while (std::getline(ss, tok, ',')) {
    if (tok.empty()) continue;
    char* end = nullptr;
    const double v = std::strtod(tok.c_str(), &end);
    if (end != tok.c_str() + tok.size() || !(v > 0)) {
      throw std::runtime_error("bad window '" + tok + "' (expected positive numbers)");
    }
    out.push_back(v);
  }
  return out;
}

std::string FindPython() {
  if (!FLAGS_python.empty()) return FLAGS_python;
  for (const char* p : {"python3", "/usr/bin/python3"}) {
    const std::string cmd = std::string(p) + " -c 'import matplotlib' >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0) return p;
  }
  return "";
}

}  // namespace

constexpr char kUsage[] =
    "ctlio_evaluate: ATE and RPE of an estimated trajectory against a reference (TUM or\n"
    "KITTI files); with --output_dir also metrics.txt, metrics.json, errors.csv and plots.\n"
    "\n"
    "  ctlio_evaluate --estimate=est.tum --reference=gt.tum [--align=se3|sim3|none]\n"
    "  ctlio_evaluate --estimate=est.tum --reference=gt.tum --rpe_distances=10,50 --output_dir=ev";

int main(int argc, char** argv) {
  ctlio::apps::ParseCommandLine(&argc, &argv, kUsage);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  if (FLAGS_estimate.empty() || FLAGS_reference.empty()) {
    std::cerr << "--estimate and --reference are required\n";
    return 2;
  }
  namespace io = ctlio::io;
  namespace ev = ctlio::eval;
  try {
    const auto est = io::ReadTrajectory(FLAGS_estimate, FLAGS_estimate_times);
    const auto ref = io::ReadTrajectory(FLAGS_reference, FLAGS_reference_times);
    const auto pairs = ev::Associate(est, ref, std::llround(FLAGS_tolerance * 1e9));
    if (pairs.size() < 3) {
      throw std::runtime_error("only " + std::to_string(pairs.size()) +
                               " poses associated within " + std::to_string(FLAGS_tolerance) +
                               " s: check the time bases of the two files");
    }
    std::vector<io::StampedPose> e, r;
    for (const auto& [i, j] : pairs) e.push_back(est[i]), r.push_back(ref[j]);
    ev::Report report;
    report.estimate_path = FLAGS_estimate;
    report.reference_path = FLAGS_reference;
    report.estimate_poses = est.size();
    report.reference_poses = ref.size();
    report.associated = pairs.size();
    report.tolerance_s = FLAGS_tolerance;
    report.alignment = FLAGS_align;
    report.ate = ev::ComputeAte(e, r, ev::ParseAlignmentMode(FLAGS_align));
    // RPE is alignment-free; with Sim(3) the estimate's relative motions are scaled first.
    std::vector<io::StampedPose> e_rpe = e;
    if (FLAGS_align == "sim3") {
      for (auto& p : e_rpe) {
        p.pose = ctlio::SE3(p.pose.rotation(), report.ate.alignment.scale * p.pose.translation());
      }
    }
    for (double d : ParseList(FLAGS_rpe_distances)) {
      report.rpe.push_back(ev::ComputeRpeDistance(e_rpe, r, d));
    }
    for (double t : ParseList(FLAGS_rpe_times))
      report.rpe.push_back(ev::ComputeRpeTime(e_rpe, r, t));
    const std::string text = ev::ReportText(report);
    std::cout << text;
    if (!FLAGS_output_dir.empty()) {
      namespace fs = std::filesystem;
      const fs::path out(FLAGS_output_dir);
      fs::create_directories(out);
      io::WriteTextFile((out / "metrics.txt").string(), text);
      io::WriteTextFile((out / "metrics.json").string(), ev::ReportJson(report));
      {
        const std::string csv_path = (out / "errors.csv").string();
        std::ofstream csv = io::OpenForWriting(csv_path);
        csv << "t_s,est_x,est_y,est_z,ref_x,ref_y,ref_z,error_m\n";
        csv.precision(12);
        const auto& a = report.ate;
        for (size_t k = 0; k < a.errors.size(); ++k) {
          csv << io::FormatSecondsNs(a.times_ns[k]) << ',' << a.estimate_aligned[k].x() << ','
              << a.estimate_aligned[k].y() << ',' << a.estimate_aligned[k].z() << ','
              << a.reference[k].x() << ',' << a.reference[k].y() << ',' << a.reference[k].z() << ','
              << a.errors[k] << '\n';
        }
        io::CloseChecked(csv, csv_path);
      }
      std::cout << "wrote " << (out / "metrics.txt").string() << ", metrics.json, errors.csv\n";
      if (FLAGS_plot) {
        const std::string py = FindPython();
        if (py.empty()) {
          std::cout << "plots skipped: no python3 with matplotlib found "
                       "(apt install python3-matplotlib, or pass --python)\n";
        } else if (!fs::exists(FLAGS_plot_script)) {
          std::cout << "plots skipped: " << FLAGS_plot_script << " not found (--plot_script)\n";
        } else {
          const std::string cmd = py + " '" + FLAGS_plot_script + "' '" +
                                  (out / "errors.csv").string() + "' '" + out.string() + "'";
          if (std::system(cmd.c_str()) == 0) {
            std::cout << "wrote top_view.png, error_over_time.png\n";
          } else {
            // The plots were asked for and python is there: a failure (e.g. a full disk) is an
            // error, not a silently missing PNG.
            throw std::runtime_error(out.string() + ": the plot script failed (" + cmd + ")");
          }
        }
      }
    }
  } catch (const std::exception& ex) {
    std::cerr << "ctlio_evaluate: " << ex.what() << "\n";
    return 1;
  }
  return 0;
}
