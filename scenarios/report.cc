#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "scenarios/html.h"
#include "scenarios/plot.h"
#include "scenarios/run_recorder.h"
#include "scenarios/scenario_result.h"
#include "slam/eval/json_writer.h"
#include "slam/eval/nees.h"
#include "slam/eval/pose_association.h"
#include "slam/fusion/consistency.h"
#include "slam/io/atomic_file.h"
#include "slam/io/map_image.h"
#include "slam/io/map_server.h"
#include "slam/io/tum_io.h"
#include "slam/types/thread_pool.h"

namespace slamrig::scenario {
namespace {

namespace fs = std::filesystem;

std::string Number(double v, const char* format = "%.4g") {
  if (!std::isfinite(v)) return "n/a";
  char buffer[32];
  // Counts (scans, resamples) in full rather than as 2.106e+04.
  if (std::abs(v) >= 1e4 && std::abs(v) < 1e12 && v == std::floor(v)) {
    std::snprintf(buffer, sizeof(buffer), "%.0f", v);
    return buffer;
  }
  std::snprintf(buffer, sizeof(buffer), format, v);
  return buffer;
}

// Position and heading error of `estimate` against `truth`, pose for pose as evaluation pairs
// them, over time since the first reference pose.
void ErrorsOverTime(const Trajectory& estimate, const Trajectory& truth, std::vector<double>* t,
                    std::vector<double>* position, std::vector<double>* heading) {
  const double t0 = truth.empty() ? 0.0 : truth[0].time.seconds();
  for (const slam::PosePair& p : slam::AssociatePoses(estimate, truth)) {
    t->push_back(p.time.seconds() - t0);
    position->push_back((p.reference.translation() - p.estimate.translation()).norm());
    heading->push_back(std::abs(NormalizeAngle(p.reference.theta() - p.estimate.theta())));
  }
}

// Every metric some configuration has, in KnownMetrics() order first, then the others.
std::vector<std::string> AllMetrics(const ScenarioResult& r) {
  const auto any_has = [&](const std::string& name) {
    return std::any_of(r.configs.begin(), r.configs.end(),
                       [&](const ConfigResult& c) { return c.metrics.count(name) > 0; });
  };
  std::vector<std::string> names;
  for (const std::string& name : KnownMetrics())
    if (any_has(name)) names.push_back(name);
  for (const ConfigResult& c : r.configs) {
    for (const auto& [name, value] : c.metrics) {
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    }
  }
  return names;
}

const char* OdometrySourceName(slam::OdometrySource s) {
  switch (s) {
    case slam::OdometrySource::kWheelTicks:
      return "wheel_ticks";
    case slam::OdometrySource::kOdometryPoses:
      return "poses";
    case slam::OdometrySource::kNone:
      return "none";
    case slam::OdometrySource::kAuto:
      break;
  }
  return "auto";
}

// How a configuration ran (not a metric: no expectation takes these): the odometry it used,
// the wall time it took, what the synchroniser and the log's stamps did, its map's raster.
void WriteRunFacts(const ConfigResult& c, slam::JsonWriter* j) {
  j->BeginObject("run")
      .String("odometry_source", OdometrySourceName(c.run.odometry_source))
      .Number("wall_time_s", c.run.wall_s)
      .Integer("poses", static_cast<long long>(c.estimate.size()))
      .Integer("gyro_fallbacks", c.run.gyro_fallbacks)
      .Integer("scans_without_odometry", c.run.scans_without_odometry)
      .Integer("out_of_order_stamps", c.run.final.out_of_order());
  if (const auto& m = c.run.scan_matched_odometry) {
    // Without odometry: how the scan-matched motion prior placed the scans.
    j->BeginObject("scan_matched_odometry")
        .Integer("scans", m->scans)
        .Integer("matched", m->matched)
        .Integer("degenerate", m->degenerate)
        .Integer("failed", m->failed)
        .Integer("no_points", m->no_points)
        .EndObject();
  }
  if (c.run.judges_itself) {
    // The estimator's lost intervals, seconds since its first scan.
    std::vector<double> from_s, to_s;
    for (const slam::LostInterval& interval : c.run.lost_intervals) {
      from_s.push_back(SecondsBetween(interval.from, c.run.online[0].time));
      to_s.push_back(SecondsBetween(interval.to, c.run.online[0].time));
    }
    j->NumberArray("lost_from_s", from_s).NumberArray("lost_to_s", to_s);
  }
  j->BeginObject("map")
      .Number("resolution_m", c.run.map.resolution())
      .Integer("width", c.run.map.width())
      .Integer("height", c.run.map.height())
      .EndObject();
  j->EndObject();
}

// The one metrics.json schema of `slamrig run` and `slamrig slam` (see the pipeline notes).
std::string MetricsJson(const ScenarioResult& r) {
  slam::JsonWriter j;
  j.String("scenario", r.spec->name)
      .Integer("seed", static_cast<long long>(r.spec->seed))
      .String("source", r.spec->simulated ? "simulation" : r.spec->log->path)
      .String("log_format", r.spec->simulated ? "" : r.log_format)
      .String("reference", r.truth.empty() ? "" : r.reference_kind)
      .Bool("passed", r.passed)
      .Number("sim_time_s", r.sim_time_s)
      .Bool("times_synthesised", r.times_synthesised)
      .Integer("scans", r.scans)
      .Integer("scans_blacked_out", r.scans_blacked_out)
      .Integer("kidnaps", r.kidnaps_done)
      .Integer("rgbd_frames", r.frames);
  if (!r.truth_metrics.empty()) {
    j.BeginObject("truth");
    for (const auto& [name, value] : r.truth_metrics) j.Number(name, value);
    j.EndObject();
  }
  j.BeginObject("configs");
  for (const ConfigResult& c : r.configs) {
    j.BeginObject(c.name);
    j.String("algorithm", c.algorithm);
    for (const auto& [name, value] : c.metrics) j.Number(name, value);
    WriteRunFacts(c, &j);
    j.BeginObject("config");
    for (const slam::EstimatorConfig& config : r.spec->configs) {
      if (config.name == c.name) slam::WriteEstimatorConfigJson(config, &j);
    }
    j.EndObject();
    j.EndObject();
  }
  // A failed configuration: what went wrong instead of metrics.
  for (const ConfigFailure& f : r.failures) {
    j.BeginObject(f.name);
    j.String("algorithm", f.algorithm).String("failure", f.message);
    j.BeginObject("config");
    for (const slam::EstimatorConfig& config : r.spec->configs) {
      if (config.name == f.name) slam::WriteEstimatorConfigJson(config, &j);
    }
    j.EndObject();
    j.EndObject();
  }
  j.EndObject();
  j.BeginObject("expectations");
  for (const ExpectationOutcome& o : r.outcomes) {
    j.BeginObject(o.expectation.config + "." + o.expectation.metric +
                  (o.expectation.is_max ? "_max" : "_min"))
        .Number("threshold", o.expectation.threshold)
        .Number("value", o.value)
        .Bool("passed", o.passed)
        .EndObject();
  }
  j.EndObject();
  j.StringArray("notes", r.notes);
  return j.Finish();
}

// The 3-sigma ellipse of a 2D covariance, as a closed polyline of segments.
void AddEllipse(const Eigen::Vector2d& center, const Eigen::Matrix2d& covariance, Colour colour,
                std::vector<slam::SegmentOverlay>* out) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(covariance);
  const Eigen::Vector2d radii = 3.0 * eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  const Eigen::Matrix2d axes = eigen.eigenvectors();
  constexpr int kSides = 24;
  const auto point = [&](int k) {
    const double a = 2.0 * M_PI * k / kSides;
    return Eigen::Vector2d(center +
                           axes * Eigen::Vector2d(radii(0) * std::cos(a), radii(1) * std::sin(a)));
  };
  for (int k = 0; k < kSides; ++k)
    out->push_back({point(k), point(k + 1), colour.b, colour.g, colour.r});
}

// A small cross marking a point (a landmark, a true pillar), `size_m` across.
void AddCross(const Eigen::Vector2d& c, double size_m, Colour colour,
              std::vector<slam::SegmentOverlay>* out) {
  const double h = 0.5 * size_m;
  out->push_back(
      {c - Eigen::Vector2d(h, h), c + Eigen::Vector2d(h, h), colour.b, colour.g, colour.r});
  out->push_back(
      {c - Eigen::Vector2d(h, -h), c + Eigen::Vector2d(h, -h), colour.b, colour.g, colour.r});
}

// A landmark estimator's map in the map frame: one line per landmark, its covariance and its
// sightings.
std::string LandmarksCsv(const ConfigResult& c) {
  const Eigen::Matrix2d rotation = c.map_from_estimator.Rotation();
  std::vector<int> sightings(c.run.landmarks.landmarks.size(), 0);
  for (const slam::LandmarkSighting& s : c.run.landmarks.sightings)
    if (s.landmark >= 0 && s.landmark < static_cast<int>(sightings.size())) ++sightings[s.landmark];
  std::ostringstream out;
  out.precision(9);
  out << "# index,x_m,y_m,xx,xy,yy,sightings (map frame, m and m^2)\n";
  for (std::size_t i = 0; i < c.run.landmarks.landmarks.size(); ++i) {
    const slam::LandmarkEstimate& l = c.run.landmarks.landmarks[i];
    const Eigen::Vector2d p = c.map_from_estimator * l.position_m;
    const Eigen::Matrix2d q = rotation * l.covariance * rotation.transpose();
    out << i << ',' << p.x() << ',' << p.y() << ',' << q(0, 0) << ',' << q(0, 1) << ',' << q(1, 1)
        << ',' << sightings[i] << '\n';
  }
  return out.str();
}

}  // namespace

std::string ExpectationOutcome::Describe() const {
  const Expectation& e = expectation;
  const std::string name = e.config + "." + e.metric;
  if (!std::isfinite(value))
    return name + " = n/a (not computed): fails " + (e.is_max ? "<= " : ">= ") +
           Number(e.threshold);
  const char* op = passed ? (e.is_max ? "<=" : ">=") : (e.is_max ? ">" : "<");
  std::string text = name + " = " + Number(value) + " " + op + " " + Number(e.threshold);
  if (!passed) {
    const double by = std::abs(value - e.threshold);
    const double percent = e.threshold != 0.0 ? 100.0 * by / std::abs(e.threshold) : NAN;
    text += " (" + std::string(e.is_max ? "over" : "under") + " by " + Number(by) +
            (std::isfinite(percent) ? ", " + Number(percent, "%.0f") + " %" : "") + ")";
  }
  return text;
}

void CheckExpectations(ScenarioResult* result) {
  result->outcomes.clear();
  result->passed = true;
  for (const Expectation& e : result->spec->expectations) {
    ExpectationOutcome o;
    o.expectation = e;
    o.value = NAN;
    bool found = false;
    for (const ConfigResult& c : result->configs) {
      if (c.name != e.config) continue;
      found = true;
      const auto it = c.metrics.find(e.metric);
      if (it != c.metrics.end()) o.value = it->second;
    }
    if (!found && e.config == "truth") {
      const auto it = result->truth_metrics.find(e.metric);
      if (it != result->truth_metrics.end()) o.value = it->second;
    }
    o.passed =
        std::isfinite(o.value) && (e.is_max ? o.value <= e.threshold : o.value >= e.threshold);
    result->passed = result->passed && o.passed;
    result->outcomes.push_back(o);
  }
  if (!result->failures.empty()) result->passed = false;
}

std::string ExpectationTable(const ScenarioResult& r) {
  std::string out;
  for (const ConfigFailure& f : r.failures)
    out += "  FAIL   " + f.name + " (" + f.algorithm + ") failed: " + f.message + "\n";
  if (r.outcomes.empty()) return out + "  (no expectations)\n";
  std::size_t width = 0;
  for (const auto& o : r.outcomes)
    width = std::max(width, o.expectation.config.size() + o.expectation.metric.size() + 1);
  char line[256];
  std::snprintf(line, sizeof(line), "  %-6s %-*s %12s %12s\n", "", static_cast<int>(width),
                "expectation", "value", "bound");
  out += line;
  for (const auto& o : r.outcomes) {
    const std::string name = o.expectation.config + "." + o.expectation.metric;
    const std::string bound =
        std::string(o.expectation.is_max ? "<= " : ">= ") + Number(o.expectation.threshold);
    std::snprintf(line, sizeof(line), "  %-6s %-*s %12s %12s%s\n", o.passed ? "PASS" : "FAIL",
                  static_cast<int>(width), name.c_str(), Number(o.value).c_str(), bound.c_str(),
                  o.passed ? "" : ("   <- " + o.Describe()).c_str());
    out += line;
  }
  return out;
}

namespace {

// A file of the report folder.
class Folder {
 public:
  explicit Folder(const std::string& dir) : dir_(dir) {}
  std::string operator()(const std::string& name) const { return (dir_ / name).string(); }
  void WritePng(const std::string& name, const cv::Mat3b& rgb) const {
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    std::vector<std::uint8_t> png;
    cv::imencode(".png", bgr, png);
    slam::WriteFileAtomically((*this)(name), std::string(png.begin(), png.end()));
  }

 private:
  fs::path dir_;
};

// Configuration i's colour: the palette, skipping its green (the truth's).
Colour ConfigColour(std::size_t i) { return PaletteColour(i == 2 ? 4 : i); }

std::string Figure(const std::string& png, const std::string& caption = "") {
  return "<figure><img src=\"" + png + "\">" +
         (caption.empty() ? "" : "<figcaption>" + caption + "</figcaption>") + "</figure>";
}

// Each configuration's trajectories (final, online where it revised its past), covariances,
// landmarks and map (map_server), in the map frame.
void WriteConfigFiles(const ScenarioResult& r, const Folder& file) {
  for (const ConfigResult& c : r.configs) {
    slam::WriteTum(file(c.name + ".tum"), c.estimate);
    if (c.run.final.poses() != c.run.online.poses()) {
      slam::WriteTum(file(c.name + "_online.tum"), c.online);
    }
    if (!c.run.covariances.empty()) {
      std::vector<Eigen::Matrix3d> in_map;
      for (const Eigen::Matrix3d& p : c.run.covariances)
        in_map.push_back(slam::RotateCovariance(p, c.map_from_estimator.theta()));
      slam::WriteFileAtomically(file(c.name + "_covariance.csv"),
                                slam::CovarianceCsv(c.online, in_map));
    }
    if (!c.run.landmarks.landmarks.empty()) {
      slam::WriteFileAtomically(file(c.name + "_landmarks.csv"), LandmarksCsv(c));
    }
    if (r.scans > 0) slam::WriteMapServerMap(c.run.map, file(c.name + "_map"));
  }
}

// The overlays of a configuration's own map: its loop closures (green when the reference agrees
// or there is none, red not) and, for a landmark estimator, its landmarks with 3-sigma ellipses,
// the true pillars (green crosses) and the last pose's 3-sigma position ellipse.
std::vector<slam::SegmentOverlay> OwnMapSegments(const ScenarioResult& r, const ConfigResult& c) {
  std::vector<slam::SegmentOverlay> segments;
  const auto& final_poses = c.run.final.poses();
  for (std::size_t k = 0; k < c.run.loop_closures.size(); ++k) {
    const slam::LoopClosure& loop = c.run.loop_closures[k];
    if (loop.from_scan < 0 || loop.to_scan < 0 ||
        static_cast<std::size_t>(std::max(loop.from_scan, loop.to_scan)) >= final_poses.size()) {
      continue;
    }
    const bool ok = k >= c.loop_is_true.size() || c.loop_is_true[k];
    segments.push_back({final_poses[loop.from_scan].pose.translation(),
                        final_poses[loop.to_scan].pose.translation(), 0,
                        static_cast<std::uint8_t>(ok ? 170 : 0),
                        static_cast<std::uint8_t>(ok ? 0 : 220)});
  }
  if (c.run.landmarks.landmarks.empty()) return segments;
  const Colour mark = PaletteColour(3);
  for (const slam::LandmarkEstimate& l : c.run.landmarks.landmarks) {
    AddCross(l.position_m, 0.4, mark, &segments);
    AddEllipse(l.position_m, l.covariance, mark, &segments);
  }
  if (r.spec->simulated) {
    const Pose2 estimator_from_map = c.map_from_estimator.Inverse();
    for (const sim::ShapeSpec& shape : r.spec->simulated->options.world.walls) {
      if (shape.type == sim::ShapeType::kCircle)
        AddCross(estimator_from_map * shape.center_m, 0.6, {40, 160, 40}, &segments);
    }
  }
  if (!c.run.covariances.empty() && !c.run.online.empty()) {
    AddEllipse(c.run.online.poses().back().pose.translation(),
               c.run.covariances.back().topLeftCorner<2, 2>(), mark, &segments);
  }
  return segments;
}

// map.png (the truth map, or the first configuration's, under every trajectory) and each
// configuration's own map with its trajectory and the truth in its frame; their figures.
std::string MapsHtml(const ScenarioResult& r, const Folder& file) {
  const slam::OccupancyGrid* background = r.truth_map ? &*r.truth_map : nullptr;
  if (!background && !r.configs.empty()) background = &r.configs.front().run.map;
  if (!background || r.scans == 0) return "";  // no scan, no map
  const slam::TrajectoryOverlay truth_overlay{&r.truth, r.reference_kind, 40, 160, 40};
  std::vector<slam::TrajectoryOverlay> overlays = {truth_overlay};
  for (std::size_t i = 0; i < r.configs.size(); ++i) {
    const Colour colour = ConfigColour(i);
    overlays.push_back({&r.configs[i].estimate, r.configs[i].name, colour.b, colour.g, colour.r});
  }
  const std::string truth_source = r.spec->simulated ? "true poses" : r.reference_kind;
  // The images are drawn and encoded side by side, each into its own file.
  std::vector<std::function<void()>> images;
  slam::MapImageOptions options;
  options.title = r.spec->name + ": map from " + truth_source + ", trajectories overlaid";
  images.emplace_back(
      [&, options] { slam::WriteMapPng(file("map.png"), *background, overlays, options); });
  std::string html = Figure("map.png", "The map from the " + EscapeHtml(truth_source) +
                                           " with the reference and estimated trajectories.");
  for (std::size_t i = 0; i < r.configs.size(); ++i) {
    const ConfigResult& c = r.configs[i];
    slam::MapImageOptions own;
    own.title = c.name + ": its own map and trajectory";
    own.segments = OwnMapSegments(r, c);
    images.emplace_back([&, i, own] {
      // The estimator's map is in its own frame: bring both trajectories there.
      const Pose2 estimator_from_map = c.map_from_estimator.Inverse();
      Trajectory truth_local, estimate_local;
      for (const auto& p : r.truth.poses()) truth_local.Append(p.time, estimator_from_map * p.pose);
      for (const auto& p : c.estimate.poses())
        estimate_local.Append(p.time, estimator_from_map * p.pose);
      slam::TrajectoryOverlay truth_here = truth_overlay, estimate_here = overlays[i + 1];
      truth_here.trajectory = &truth_local;
      estimate_here.trajectory = &estimate_local;
      slam::WriteMapPng(file(c.name + "_map.png"), c.run.map, {truth_here, estimate_here}, own);
    });
    const bool has_landmarks = !c.run.landmarks.landmarks.empty();
    html += Figure(c.name + "_map.png",
                   EscapeHtml(c.name) + "'s map with its trajectory" +
                       (r.truth.empty() ? "" : " (and the reference, in green)") +
                       (has_landmarks ? "; its landmarks (crosses) with 3-sigma ellipses, the "
                                        "true pillars (green crosses) and the last pose's "
                                        "3-sigma ellipse"
                                      : "") +
                       ".");
  }
  slam::RunTasks(images, slam::DefaultThreadCount());
  return html;
}

// The floor texture: the truth, the map from the true poses, each configuration's map.
std::string TextureHtml(const ScenarioResult& r, const Folder& file) {
  std::string html;
  if (r.true_texture && r.truth_texture) {
    file.WritePng("texture_truth.png", *r.true_texture);
    file.WritePng("texture_true_poses.png", r.truth_texture->colors);
    html += Figure("texture_truth.png", "The true floor texture.") +
            Figure("texture_true_poses.png",
                   "The texture map from the true poses (PSNR " +
                       Number(r.truth_texture->score.psnr_db.value_or(NAN)) + " dB, coverage " +
                       Number(r.truth_texture->score.coverage) + ").");
  }
  for (const ConfigResult& c : r.configs) {
    if (!c.texture) continue;
    file.WritePng(c.name + "_texture.png", c.texture->colors);
    html += Figure(c.name + "_texture.png",
                   EscapeHtml(c.name) +
                       "'s texture map from its final poses, in the frame ATE aligns them to "
                       "(PSNR " +
                       Number(c.texture->score.psnr_db.value_or(NAN)) + " dB).");
  }
  return html;
}

// Position and heading error over time, per configuration (a run with a reference).
std::string ErrorPlotsHtml(const ScenarioResult& r, const Folder& file) {
  if (r.truth.empty()) return "";
  std::vector<PlotSeries> position, heading;
  for (std::size_t i = 0; i < r.configs.size(); ++i) {
    const ConfigResult& c = r.configs[i];
    PlotSeries p{c.name, {}, {}, {}, {}, ConfigColour(i)};
    PlotSeries h = p;
    ErrorsOverTime(c.estimate, r.truth, &p.x, &p.y, &h.y);
    h.x = p.x;
    for (double& v : h.y) v = v * 180.0 / M_PI;
    position.push_back(std::move(p));
    heading.push_back(std::move(h));
  }
  PlotOptions options;
  options.title = "Position error (estimate vs truth, same start pose)";
  options.x_label = "time [s]";
  options.y_label = "error [m]";
  slam::WriteFileAtomically(file("position_error.png"), RenderLinePlotPng(position, options));
  options.title = "Heading error";
  options.y_label = "error [deg]";
  slam::WriteFileAtomically(file("heading_error.png"), RenderLinePlotPng(heading, options));
  return Figure("position_error.png") + Figure("heading_error.png");
}

// The pose NEES over time with chi2_3's two-sided 95 % region (Bar-Shalom et al., Sec. 5.4.2).
std::string NeesPlotHtml(const ScenarioResult& r, const Folder& file) {
  std::vector<PlotSeries> nees;
  for (std::size_t i = 0; i < r.configs.size(); ++i) {
    const ConfigResult& c = r.configs[i];
    if (c.nees.empty()) continue;
    std::vector<double> t = c.nees_time_s;
    for (double& v : t) v -= r.truth.empty() ? 0.0 : r.truth[0].time.seconds();
    // On a log scale: an inconsistent filter's NEES runs to thousands.
    std::vector<double> log_nees;
    for (double v : c.nees) log_nees.push_back(std::log10(std::max(v, 1e-6)));
    nees.push_back({c.name, t, log_nees, {}, {}, ConfigColour(i)});
  }
  if (nees.empty()) return "";
  const slam::NeesBounds bounds = slam::AneesBounds(3, 1);
  const std::vector<double> span = {nees.front().x.front(), nees.front().x.back()};
  const double lower = std::log10(bounds.lower), upper = std::log10(bounds.upper);
  nees.push_back({"95 % lower", span, {lower, lower}, {}, {}, PaletteColour(3), false, true});
  nees.push_back({"95 % upper", span, {upper, upper}, {}, {}, PaletteColour(3), false, true});
  PlotOptions options;
  options.title = "Pose NEES e^T P^-1 e (3 dof, log10) with the chi-square 95 % region";
  options.x_label = "time [s]";
  options.y_label = "log10 NEES";
  options.y_from_zero = false;
  slam::WriteFileAtomically(file("nees.png"), RenderLinePlotPng(nees, options));
  return Figure("nees.png");
}

// Every per-scan trace the estimators report (a PF's Neff, ...), one plot per name.
std::string TracePlotsHtml(const ScenarioResult& r, const Folder& file) {
  std::map<std::string, std::vector<PlotSeries>> traces;
  const double t0 = r.truth.empty() ? 0.0 : r.truth[0].time.seconds();
  for (std::size_t i = 0; i < r.configs.size(); ++i) {
    const ConfigResult& c = r.configs[i];
    std::vector<double> t = c.run.trace_time_s;
    for (double& v : t) v -= t0;
    for (const auto& [name, values] : c.run.traces)
      traces[name].push_back({c.name, t, values, {}, {}, ConfigColour(i)});
  }
  std::string html;
  PlotOptions options;
  options.x_label = "time [s]";
  for (const auto& [name, series] : traces) {
    options.title = name == "neff" ? "Effective sample size Neff = 1 / sum(w^2) after each scan"
                                   : name + " after each scan";
    options.y_label = name == "neff" ? "Neff" : name;
    slam::WriteFileAtomically(file(name + ".png"), RenderLinePlotPng(series, options));
    html += Figure(name + ".png");
  }
  return html;
}

// The trajectory errors side by side (configurations scored against a reference).
std::string ErrorsByConfigHtml(const ScenarioResult& r, const Folder& file) {
  std::vector<std::string> names;
  std::vector<std::vector<double>> values;
  for (const ConfigResult& c : r.configs) {
    if (!c.metrics.count("ate_rmse_m")) continue;
    names.push_back(c.name);
    auto get = [&](const char* m) {
      const auto it = c.metrics.find(m);
      return it == c.metrics.end() ? NAN : it->second;
    };
    values.push_back(
        {get("ate_rmse_m"), get("ate_max_m"), get("rpe_m_per_10m"), get("final_error_m")});
  }
  if (names.empty()) return "";
  PlotOptions options;
  options.title = "Trajectory errors per SLAM configuration";
  options.y_label = "metres";
  slam::WriteFileAtomically(
      file("errors_by_config.png"),
      RenderBarChartPng(names, {"ATE RMSE", "ATE max", "RPE per 10 m", "final error"}, values,
                        options));
  return Figure("errors_by_config.png");
}

// The run in one sentence, and the files to download.
std::string SummaryHtml(const ScenarioResult& r) {
  std::ostringstream h;
  h << "<p>Seed " << r.spec->seed << ", ";
  if (r.times_synthesised) {
    h << EscapeHtml(r.spec->log->path)
      << " (times synthesised from line order; no real-time factor)";
  } else {
    h << Number(r.sim_time_s, "%.1f")
      << (r.spec->simulated ? " s simulated" : " s of " + EscapeHtml(r.spec->log->path));
  }
  h << ", " << r.scans << " scans";
  if (r.scans_blacked_out) h << " (" << r.scans_blacked_out << " blacked out)";
  if (r.kidnaps_done) h << ", " << r.kidnaps_done << " kidnapping(s)";
  h << ". Files: <a href=\"config.yaml\">config.yaml</a>, <a "
       "href=\"metrics.json\">metrics.json</a>";
  if (!r.truth.empty()) h << ", <a href=\"truth.tum\">truth.tum</a>";
  for (const auto& c : r.configs)
    h << ", <a href=\"" << c.name << ".tum\">" << c.name << ".tum</a>";
  if (!r.recording.empty()) {
    h << ", <a href=\"run.mcap\">run.mcap</a> (the whole run for Foxglove: open it with the "
         "layout foxglove/slamrig.json)";
  }
  h << ".</p>";
  return h.str();
}

// The expectations (when there are any) and the metrics: a row per metric some configuration
// has, a blank cell where one does not have it.
// Where each estimator that judges itself said it was lost (seconds since its first scan).
std::string LostIntervalsHtml(const ScenarioResult& r) {
  std::ostringstream h;
  for (const ConfigResult& c : r.configs) {
    if (!c.run.judges_itself) continue;
    const auto diverged = c.metrics.find("diverged");
    h << "<tr><td>" << EscapeHtml(c.name) << "</td><td>"
      << (diverged != c.metrics.end() && diverged->second == 1.0 ? "yes" : "no") << "</td><td>";
    if (c.run.lost_intervals.empty()) h << "never lost";
    for (std::size_t i = 0; i < c.run.lost_intervals.size(); ++i) {
      const slam::LostInterval& interval = c.run.lost_intervals[i];
      h << (i ? ", " : "") << Number(SecondsBetween(interval.from, c.run.online[0].time), "%.1f")
        << "&ndash;" << Number(SecondsBetween(interval.to, c.run.online[0].time), "%.1f") << " s ("
        << interval.scans << (interval.scans == 1 ? " scan)" : " scans)");
    }
    h << "</td></tr>";
  }
  if (h.str().empty()) return "";
  return "<h2>Self-diagnosis</h2><table><tr><th>configuration</th><th>diverged (its own "
         "verdict)</th><th>lost intervals</th></tr>" +
         h.str() + "</table>";
}

std::string TablesHtml(const ScenarioResult& r) {
  std::ostringstream h;
  if (!r.outcomes.empty()) {
    h << "<h2>Expectations</h2><table><tr><th>expectation</th><th>value</th><th>bound</th>"
         "<th>result</th></tr>";
    for (const auto& o : r.outcomes) {
      h << "<tr><td>" << EscapeHtml(o.expectation.config + "." + o.expectation.metric)
        << "</td><td>" << Number(o.value) << "</td><td>"
        << (o.expectation.is_max ? "&le; " : "&ge; ") << Number(o.expectation.threshold)
        << "</td><td class=\"" << (o.passed ? "pass\">pass" : "fail\">FAIL") << "</td></tr>";
    }
    h << "</table>";
  }
  h << "<h2>Metrics</h2><table><tr><th>metric</th>";
  for (const auto& c : r.configs) h << "<th>" << EscapeHtml(c.name) << "</th>";
  h << "</tr>";
  for (const std::string& m : AllMetrics(r)) {
    h << "<tr><td>" << m << "</td>";
    for (const auto& c : r.configs) {
      const auto it = c.metrics.find(m);
      h << "<td>" << (it == c.metrics.end() ? "" : Number(it->second)) << "</td>";
    }
    h << "</tr>";
  }
  h << "</table>";
  h << LostIntervalsHtml(r);
  if (!r.truth_metrics.empty()) {
    h << "<h2>Texture (true poses)</h2><table><tr><th>metric</th><th>truth</th></tr>";
    for (const auto& [name, value] : r.truth_metrics)
      h << "<tr><td>" << name << "</td><td>" << Number(value) << "</td></tr>";
    h << "</table>";
  }
  return h.str();
}

}  // namespace

void WriteReport(const ScenarioResult& r, const std::string& out_dir) {
  fs::create_directories(out_dir);
  const Folder file(out_dir);
  // metrics.json, written last, marks a complete folder: an earlier run's must not vouch for
  // files this one only half replaced.
  fs::remove(file("metrics.json"));
  if (!r.recording.empty()) RunRecorder::Commit(r.recording);
  slam::WriteFileAtomically(file("config.yaml"), r.spec->resolved_yaml);
  if (!r.truth.empty()) slam::WriteTum(file("truth.tum"), r.truth);
  // The files, each section's own, are written side by side.
  std::string maps, texture, plots;
  const std::function<void()> sections[] = {
      [&] { maps = MapsHtml(r, file); }, [&] { WriteConfigFiles(r, file); },
      [&] { texture = TextureHtml(r, file); },
      [&] {
        plots = ErrorPlotsHtml(r, file) + NeesPlotHtml(r, file) + TracePlotsHtml(r, file) +
                ErrorsByConfigHtml(r, file);
      }};
  slam::RunTasks(sections, slam::DefaultThreadCount());

  std::ostringstream h;
  h << "<!doctype html><html><head><meta charset=\"utf-8\"><title>" << EscapeHtml(r.spec->name)
    << "</title><style>body{font-family:sans-serif;margin:2em;max-width:1100px}"
       "img{max-width:100%;border:1px solid #ddd}figure{margin:1em 0}"
       "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:4px "
       "10px;text-align:right}"
       "th:first-child,td:first-child{text-align:left}.pass{color:#080;font-weight:bold}"
       ".fail{color:#c00;font-weight:bold}</style></head><body>";
  h << "<h1>" << EscapeHtml(r.spec->name) << " <span class=\""
    << (r.passed ? "pass\">PASS" : "fail\">FAIL") << "</span></h1>";
  if (!r.spec->description.empty()) h << "<p>" << EscapeHtml(r.spec->description) << "</p>";
  if (!r.failures.empty()) {
    h << "<h2>Failed configurations</h2><ul>";
    for (const ConfigFailure& f : r.failures) {
      h << "<li class=\"fail\">" << EscapeHtml(f.name) << " (" << EscapeHtml(f.algorithm)
        << "): " << EscapeHtml(f.message) << "</li>";
    }
    h << "</ul>";
  }
  h << SummaryHtml(r) << TablesHtml(r);
  if (!r.notes.empty()) {
    h << "<h2>Notes</h2><ul>";
    for (const std::string& note : r.notes) h << "<li>" << EscapeHtml(note) << "</li>";
    h << "</ul>";
  }
  if (!maps.empty()) h << "<h2>Maps</h2>" << maps;
  if (!texture.empty()) h << "<h2>Floor texture</h2>" << texture;
  if (!plots.empty()) h << "<h2>Errors</h2>" << plots;
  h << "</body></html>\n";
  slam::WriteFileAtomically(file("report.html"), h.str());
  // Last: its presence means the folder is complete.
  slam::WriteFileAtomically(file("metrics.json"), MetricsJson(r));
}

}  // namespace slamrig::scenario
