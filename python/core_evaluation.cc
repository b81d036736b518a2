// slamrig._core: trajectory, map, loop-closure and consistency scores.

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <tuple>
#include <vector>

#include "python/core_internal.h"
#include "slam/eval/loop_closure_score.h"
#include "slam/eval/map_score.h"
#include "slam/fusion/consistency.h"
#include "slam/grid/occupancy_grid.h"
#include "slam/types/error.h"

namespace slamrig::python {

using slam::OccupancyGrid;

void DefineEvaluation(py::module_& m) {
  m.def(
      "ate",
      [](py::handle estimate, py::handle reference) {
        const auto r = slam::ComputeAte(ToTrajectory(estimate), ToTrajectory(reference));
        py::dict d;
        d["translation"] = StatsDict(r.translation_m);
        d["rotation"] = StatsDict(r.rotation_rad);
        d["reference_from_estimate"] = r.reference_from_estimate;
        return d;
      },
      py::arg("estimate"), py::arg("reference"),
      "ATE after SE(2) alignment; trajectories as Trajectory or (N, 4) t, x, y, yaw arrays.");
  m.def(
      "rpe",
      [](py::handle estimate, py::handle reference, double distance_m) {
        const auto r =
            slam::ComputeRpe(ToTrajectory(estimate), ToTrajectory(reference), distance_m);
        py::dict d;
        d["distance_m"] = r.distance_m;
        d["translation"] = StatsDict(r.translation_m);
        d["rotation"] = StatsDict(r.rotation_rad);
        return d;
      },
      py::arg("estimate"), py::arg("reference"), py::arg("distance_m") = 0.0,
      "RPE over pose pairs `distance_m` apart along the reference (0: consecutive poses).");
  m.def(
      "score_map",
      [](const OccupancyGrid& estimate, const OccupancyGrid& truth,
         const Pose2& truth_from_estimate, int tolerance_cells, double occupied_probability) {
        slam::MapScoreOptions options;
        options.tolerance_cells = tolerance_cells;
        options.occupied_probability = occupied_probability;
        for (const auto& e : options.Validate()) throw ConfigError(e);
        const auto s = slam::ScoreMap(estimate, truth_from_estimate, truth, options);
        py::dict d;
        d["precision"] = s.precision;
        d["recall"] = s.recall;
        d["f1"] = s.f1;
        d["iou"] = s.iou;
        d["estimate_occupied"] = s.estimate_occupied;
        d["truth_occupied"] = s.truth_occupied;
        return d;
      },
      py::arg("estimate"), py::arg("truth"), py::arg("truth_from_estimate") = Pose2(),
      py::arg("tolerance_cells") = 1, py::arg("occupied_probability") = 0.65);
  m.def(
      "score_loop_closures",
      [](const std::vector<std::tuple<int, int, Pose2>>& closures, py::handle reference) {
        std::vector<slam::LoopClosure> c;
        for (const auto& [from, to, z] : closures) c.push_back({from, to, z});
        std::vector<Pose2> poses;
        const Trajectory trajectory = ToTrajectory(reference);
        for (const auto& p : trajectory.poses()) poses.push_back(p.pose);
        const auto s = slam::ScoreLoopClosures(c, poses);
        py::dict d;
        d["closures"] = s.closures;
        d["false_closures"] = s.false_closures;
        d["precision"] = s.precision;
        d["recall"] = s.recall;
        d["revisit_episodes"] = s.revisit_episodes;
        d["is_true"] = s.is_true;
        return d;
      },
      py::arg("closures"), py::arg("reference"),
      "Precision and recall of (from_scan, to_scan, Pose2) closures against one reference "
      "pose per scan.");
  m.def(
      "nees",
      [](py::array_t<double, py::array::c_style | py::array::forcecast> truth,
         py::array_t<double, py::array::c_style | py::array::forcecast> estimate,
         py::array_t<double, py::array::c_style | py::array::forcecast> covariances) {
        if (truth.ndim() != 2 || truth.shape(1) != 3 || estimate.ndim() != 2 ||
            estimate.shape(0) != truth.shape(0) || estimate.shape(1) != 3 ||
            covariances.ndim() != 3 || covariances.shape(0) != truth.shape(0) ||
            covariances.shape(1) != 3 || covariances.shape(2) != 3) {
          throw py::value_error("nees: truth and estimate (N, 3), covariances (N, 3, 3)");
        }
        const auto t = truth.unchecked<2>();
        const auto e = estimate.unchecked<2>();
        const auto c = covariances.unchecked<3>();
        py::array_t<double> out(truth.shape(0));
        auto w = out.mutable_unchecked<1>();
        for (py::ssize_t k = 0; k < truth.shape(0); ++k) {
          Eigen::Matrix3d p;
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) p(i, j) = c(k, i, j);
          w(k) =
              slam::PoseNees(Pose2(t(k, 0), t(k, 1), t(k, 2)), Pose2(e(k, 0), e(k, 1), e(k, 2)), p);
        }
        return out;
      },
      py::arg("truth"), py::arg("estimate"), py::arg("covariances"),
      "Pose NEES per row (x, y, yaw), same frame; inf where a covariance is singular.");
  m.def(
      "anees_bounds",
      [](int dimension, int runs) {
        const auto b = slam::AneesBounds(dimension, runs);
        return py::make_tuple(b.lower, b.upper);
      },
      py::arg("dimension"), py::arg("runs"), "Two-sided 95 % bounds of the average NEES.");
}

}  // namespace slamrig::python
