#pragma once

// Helpers the kinds' layouts share (layout.cc); not part of the module's interface.

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "sim/worldgen/layout.h"

namespace slamrig::sim::worldgen {

/// An opening in a wall, in metres along it; `shut`: a door leaf closes it.
struct Gap {
  double from = 0.0, to = 0.0;
  bool shut = false;
};

/// `count + 1` centre lines of corridors of `width` spread over `extent` (the first and last
/// along its edges, their free space inside [0, extent]).
std::vector<double> GridLines(double extent, double width, int count);
/// How many blocks of about `block` fit between corridors of `width` over `extent` (>= 1).
int GridCount(double extent, double width, double block);
/// Throws when an nx x ny grid of blocks has fewer than two loops, naming the size parameters.
/// (`block_pitch`: a block and a corridor, the grid's period; `what` names the kind.)
void CheckTwoLoops(int nx, int ny, const char* width_field, double width, const char* height_field,
                   double height, double block_pitch, double corridor, const std::string& what);

/// A straight axis-aligned wall whose free face runs from `a` to `b`, facing `normal` (a unit
/// axis vector), its body `thickness` behind the face, open at `gaps` (sorted, along a -> b);
/// each piece between gaps gets material().
void AddFaceWall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& normal,
                 double thickness, const std::vector<Gap>& gaps,
                 const std::function<SurfaceMaterial()>& material, Layout* layout);

/// Glass with probability `glass`, black with `black`, else matte.
std::function<SurfaceMaterial()> MaterialDraw(Rng& rng, double glass, double black);

/// Walls around [0, width] x [0, height], outside it; sets the layout's extent.
void AddOuterWalls(double width, double height, double t, Layout* layout);

}  // namespace slamrig::sim::worldgen
