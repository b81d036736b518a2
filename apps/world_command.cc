// `slamrig world generate KIND --seed N [--set KEY=VALUE] --out DIR`: a procedural world with its
// route, its map_server map and a picture (sim/worldgen).

#include <chrono>
#include <cstdio>
#include <string>

#include "apps/cli_args.h"
#include "apps/commands.h"
#include "sim/worldgen/worldgen.h"
#include "slam/io/atomic_file.h"
#include "slam/types/error.h"

namespace slamrig::app {
namespace {

int RunGenerate(const std::vector<std::string>& args) {
  std::string kind, out_dir;
  std::uint64_t seed = 1;
  std::vector<std::string> sets;
  ArgParser parser(
      "slamrig world generate", "KIND [--seed N] [--set KEY=VALUE ...] --out DIR",
      "Generates a world of KIND (" + sim::worldgen::WorldKindNames() +
          ") with a route that drives\n"
          "every corridor, aisle, street or passage and closes several loops, and writes\n"
          "DIR/world.yaml (an ordinary world file: `slamrig simulate DIR/world.yaml`, or\n"
          "`world: DIR/world.yaml` in a scenario), its map DIR/map.pgm + DIR/map.yaml "
          "(map_server)\n"
          "and a picture DIR/world.png. Same kind, seed and parameters, same bytes. --set takes\n"
          "the kind's parameters and the route's (speed_m_s, laps, robot_radius_m,\n"
          "clearance_margin_m, lookahead_m, map_resolution_m, route_length_m); see the world "
          "generator's notes.");
  parser.AddPositional("KIND", sim::worldgen::WorldKindNames(), &kind);
  parser.AddOption("seed", "N", "seed of the layout", &seed);
  parser.AddRepeated("set", "KEY=VALUE", "a parameter of the kind or the route, e.g. width_m=80",
                     &sets);
  parser.AddOption("out", "DIR", "output folder (created)", &out_dir);
  if (!parser.Parse(args)) return 0;
  if (out_dir.empty()) throw ConfigError("slamrig world generate: --out DIR is required");
  sim::worldgen::WorldKind parsed;
  if (!sim::worldgen::ParseWorldKind(kind, &parsed)) {
    throw ConfigError("slamrig world generate: KIND: unknown kind '" + kind +
                      "'; expected one of " + sim::worldgen::WorldKindNames());
  }
  YamlNode node = YamlNode::LoadString("kind: " + kind + "\nseed: " + std::to_string(seed) + "\n",
                                       "slamrig world generate");
  for (const std::string& s : sets) {
    const std::size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw ConfigError("slamrig world generate: --set " + s + ": expected KEY=VALUE");
    }
    if (s.substr(0, eq) == "kind" || s.substr(0, eq) == "seed") {
      throw ConfigError("slamrig world generate: --set " + s + ": give the " + s.substr(0, eq) +
                        (s[0] == 'k' ? " as KIND" : " with --seed"));
    }
    node.Override(s.substr(0, eq), s.substr(eq + 1), "--set " + s);
  }
  slam::CheckOutputFolder(out_dir);
  const auto start = std::chrono::steady_clock::now();
  const sim::worldgen::GenerateSpec spec = sim::worldgen::ParseGenerateSpec(node);
  node.CheckAllKeysUsed();
  sim::worldgen::GeneratedWorld world;
  try {
    world = sim::worldgen::Generate(spec);
  } catch (const sim::worldgen::ParameterError& e) {
    throw ConfigError("slamrig world generate: " + std::string(e.what()));
  }
  const double generate_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  sim::worldgen::WriteGeneratedWorld(world, out_dir);
  const double total_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "%s: %zu walls; route %.0f m a lap (%zu waypoints, %d loops, %d reversals) x %d laps at "
      "%.2f m/s; generated in %.3f s, written in %.3f s -> %s\n",
      world.world.name.c_str(), world.world.walls.size(), world.route.length_m,
      world.route.waypoints.size(), world.route.loops, world.route.reversals, world.spec.route.laps,
      world.spec.route.speed_m_s, generate_s, total_s - generate_s, out_dir.c_str());
  return 0;
}

}  // namespace

int RunWorldCommand(const std::vector<std::string>& args) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::puts(
        "Usage: slamrig world generate KIND [--seed N] [--set KEY=VALUE ...] --out DIR\n\n"
        "Subcommands:\n  generate    a procedural world, its route, map and picture\n\n"
        "Run 'slamrig world generate --help' for its arguments.");
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "generate") return RunGenerate({args.begin() + 1, args.end()});
  throw ConfigError("slamrig world: unknown subcommand '" + args[0] + "' (expected generate)");
}

}  // namespace slamrig::app
