// Turns the observation-only rawlog that MRPT's carmen2rawlog writes (an odometry reading, then
// its scan, for every laser line) into the action/sensory-frame rawlog that rbpf-slam reads: per
// scan, the odometry increment since the previous scan as a CActionRobotMovement2D (MRPT's
// default Gaussian motion model) and the scan alone in a CSensoryFrame. One entry per scan, in
// order. The scans get their stamps from TIMES (seconds, one line per scan): carmen2rawlog
// 2.5.8 gives every observation the same stamp, and icp-slam does not move the robot between
// observations with equal stamps. Built by mrpt_slam.py against the Debian MRPT headers
// (libmrpt-obs-dev).
//
//   rawlog_to_sf IN.rawlog TIMES OUT.rawlog     prints the number of scans written
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdio>
#include <exception>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: rawlog_to_sf IN.rawlog TIMES OUT.rawlog\n");
    return 2;
  }
  try {
    std::vector<double> times;
    {
      std::ifstream file(argv[2]);
      for (double t; file >> t;) times.push_back(t);
      if (!file.eof()) throw std::runtime_error(std::string("bad number in ") + argv[2]);
    }
    mrpt::io::CFileGZInputStream in;
    if (!in.open(argv[1])) throw std::runtime_error(std::string("cannot read ") + argv[1]);
    mrpt::io::CFileGZOutputStream out;
    if (!out.open(argv[3])) throw std::runtime_error(std::string("cannot write ") + argv[3]);
    auto reader = mrpt::serialization::archiveFrom(in);
    auto writer = mrpt::serialization::archiveFrom(out);

    std::optional<mrpt::poses::CPose2D> odometry, odometry_at_last_scan;
    size_t entry = 0, scans = 0;
    for (;;) {
      mrpt::obs::CActionCollection::Ptr action;
      mrpt::obs::CSensoryFrame::Ptr frame;
      mrpt::obs::CObservation::Ptr observation;
      if (!mrpt::obs::CRawlog::getActionObservationPairOrObservation(reader, action, frame,
                                                                     observation, entry))
        break;
      if (!observation) throw std::runtime_error("the input is not an observation-only rawlog");
      if (auto odo = std::dynamic_pointer_cast<mrpt::obs::CObservationOdometry>(observation)) {
        odometry = odo->odometry;
        continue;
      }
      auto scan = std::dynamic_pointer_cast<mrpt::obs::CObservation2DRangeScan>(observation);
      if (!scan) continue;
      if (!odometry)
        throw std::runtime_error("scan " + std::to_string(scans) + " has no odometry before it");
      const mrpt::poses::CPose2D increment =
          odometry_at_last_scan ? *odometry - *odometry_at_last_scan : mrpt::poses::CPose2D();
      odometry_at_last_scan = odometry;
      if (scans >= times.size())
        throw std::runtime_error("more scans than the " + std::to_string(times.size()) + " times");
      scan->timestamp = mrpt::Clock::fromDouble(times[scans]);

      mrpt::obs::CActionRobotMovement2D movement;
      movement.timestamp = scan->timestamp;
      movement.computeFromOdometry(increment,
                                   mrpt::obs::CActionRobotMovement2D::TMotionModelOptions());
      mrpt::obs::CActionCollection actions;
      actions.insert(movement);
      mrpt::obs::CSensoryFrame sf;
      sf.insert(scan);
      writer << actions << sf;
      ++scans;
    }
    if (scans != times.size())
      throw std::runtime_error(std::to_string(scans) + " scans for " +
                               std::to_string(times.size()) + " times");
    std::printf("%zu\n", scans);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rawlog_to_sf: %s\n", e.what());
    return 1;
  }
}
