#include "scenarios/sweep_summary.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

#include "scenarios/html.h"
#include "scenarios/plot.h"
#include "slam/fusion/consistency.h"
#include "slam/io/atomic_file.h"

namespace slamrig::scenario {
namespace {

namespace fs = std::filesystem;

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string Format(double v) {
  if (!std::isfinite(v)) return "n/a";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.4g", v);
  return buffer;
}

// "key=value, key=value" of the parameters `which` at `point`.
std::string Label(const SweepSpec& spec, const GridPoint& point,
                  const std::vector<std::size_t>& which) {
  std::string label;
  for (const std::size_t p : which) {
    label += (label.empty() ? "" : ", ") + spec.parameters[p].key + "=" +
             spec.parameters[p].values[point.value_index[p]];
  }
  return label;
}

// x positions of a parameter's values: the values themselves when all are numbers, else their
// index (`*numeric` says which).
std::vector<double> Positions(const SweepParameter& parameter, bool* numeric) {
  std::vector<double> xs;
  *numeric = true;
  for (const auto& v : parameter.values) {
    xs.push_back(CsvNumber(v));
    *numeric = *numeric && std::isfinite(xs.back());
  }
  if (!*numeric) {
    for (std::size_t i = 0; i < xs.size(); ++i) xs[i] = static_cast<double>(i);
  }
  return xs;
}

// One plot per metric and swept parameter: the mean over seeds with the min-max spread, one
// series per combination of the other swept parameters.
int LinePlots(const SweepSpec& spec, const SweepAggregate& a, const std::string& out_dir,
              std::string* html) {
  int plots = 0;
  for (const std::string& metric : a.metrics) {
    for (const std::size_t p : a.swept) {
      const SweepParameter& param = spec.parameters[p];
      bool numeric = true;
      const std::vector<double> xs = Positions(param, &numeric);
      std::vector<std::size_t> others;
      for (const std::size_t q : a.swept) {
        if (q != p) others.push_back(q);
      }
      std::map<std::string, PlotSeries> series;
      for (const GridPoint& point : a.points) {
        const auto stats = point.metrics.find(metric);
        if (stats == point.metrics.end()) continue;
        PlotSeries& s = series[Label(spec, point, others)];
        s.x.push_back(xs[point.value_index[p]]);
        s.y.push_back(stats->second.mean);
        s.y_low.push_back(stats->second.min);
        s.y_high.push_back(stats->second.max);
      }
      if (series.empty()) continue;
      std::vector<PlotSeries> plot;
      for (auto& [label, s] : series) {
        s.label = label.empty() ? metric : label;
        s.colour = PaletteColour(plot.size());
        s.markers = true;
        plot.push_back(std::move(s));
      }
      PlotOptions options;
      options.title = metric + " vs " + param.key;
      options.x_label = param.key + (numeric ? "" : " (index of value)");
      options.y_label = metric;
      const std::string file = "summary_" + metric + "__" + param.key + ".png";
      slam::WriteFileAtomically((fs::path(out_dir) / file).string(),
                                RenderLinePlotPng(plot, options));
      *html += "<h3>" + EscapeHtml(options.title) + "</h3><img alt=\"" + EscapeHtml(options.title) +
               "\" src=\"" + EscapeHtml(file) + "\">";
      ++plots;
    }
  }
  return plots;
}

// A table of a metric's mean over seeds, rows one swept parameter's values, columns the
// other's, each cell shaded from the lowest mean (light) to the highest (dark).
std::string HeatMap(const SweepSpec& spec, const SweepAggregate& a, const std::string& metric) {
  const SweepParameter& rows = spec.parameters[a.swept[0]];
  const SweepParameter& cols = spec.parameters[a.swept[1]];
  std::map<std::pair<std::size_t, std::size_t>, MetricStats> cells;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const GridPoint& point : a.points) {
    const auto stats = point.metrics.find(metric);
    if (stats == point.metrics.end()) continue;
    cells[{point.value_index[a.swept[0]], point.value_index[a.swept[1]]}] = stats->second;
    lo = std::min(lo, stats->second.mean);
    hi = std::max(hi, stats->second.mean);
  }
  std::string h = "<h3>" + EscapeHtml(metric) +
                  "</h3><p>Mean over seeds (small: min &ndash; max); rows " + EscapeHtml(rows.key) +
                  ", columns " + EscapeHtml(cols.key) + "; darker is higher.</p>" +
                  "<table class=\"heat\"><tr><th>" + EscapeHtml(rows.key) + " \\ " +
                  EscapeHtml(cols.key) + "</th>";
  for (const std::string& v : cols.values) h += "<th>" + EscapeHtml(v) + "</th>";
  h += "</tr>";
  for (std::size_t r = 0; r < rows.values.size(); ++r) {
    h += "<tr><th>" + EscapeHtml(rows.values[r]) + "</th>";
    for (std::size_t c = 0; c < cols.values.size(); ++c) {
      const auto it = cells.find({r, c});
      if (it == cells.end()) {
        h += "<td class=\"none\">no result</td>";
        continue;
      }
      const double t = hi > lo ? (it->second.mean - lo) / (hi - lo) : 0.5;
      char style[96];
      std::snprintf(style, sizeof(style), "background:hsl(210,70%%,%.0f%%);color:%s", 92 - 57 * t,
                    t > 0.55 ? "#fff" : "#000");
      h += std::string("<td style=\"") + style + "\">" + Format(it->second.mean) + "<br><small>" +
           Format(it->second.min) + " &ndash; " + Format(it->second.max) + "</small></td>";
    }
    h += "</tr>";
  }
  return h + "</table>";
}

// One row per grid point: each seed's verdict linked to its run's report (log.txt for a run
// that ended in an error), and what failed.
std::string RunsTable(const SweepSpec& spec, const SweepAggregate& a) {
  std::string h = "<table class=\"runs\"><tr><th>grid point</th>";
  for (const std::uint64_t seed : spec.seeds) h += "<th>seed " + std::to_string(seed) + "</th>";
  h += "<th>failed expectations</th></tr>";
  for (const GridPoint& point : a.points) {
    std::string label = Label(spec, point, a.swept);
    h += "<tr><td>" + EscapeHtml(label.empty() ? "all runs" : label) + "</td>";
    std::string failures;
    for (const SeedResult& s : point.seeds) {
      char dir[16];
      std::snprintf(dir, sizeof(dir), "runs/%04zu/", s.run_index);
      if (s.status.empty()) {
        h += "<td class=\"none\">not run</td>";
      } else if (s.status == "error") {
        h += std::string("<td class=\"error\"><a href=\"") + dir + "log.txt\">error</a></td>";
        failures += "<li>seed " + std::to_string(s.seed) + ": the run ended in an error (" +
                    "<a href=\"" + dir + "log.txt\">log</a>)</li>";
      } else {
        const bool pass = s.status == "pass";
        h += std::string("<td class=\"") + (pass ? "pass" : "fail") + "\"><a href=\"" + dir +
             "report.html\">" + (pass ? "pass" : "FAIL") + "</a></td>";
      }
      for (const ExpectationResult& e : s.failed) {
        const bool is_max = e.name.size() > 4 && e.name.compare(e.name.size() - 4, 4, "_max") == 0;
        const std::string metric = e.name.substr(0, e.name.size() - 4);
        failures += "<li>seed " + std::to_string(s.seed) + ": " + EscapeHtml(metric) + " = " +
                    Format(e.value) + ", bound " + (is_max ? "&le; " : "&ge; ") +
                    Format(e.threshold) + "</li>";
      }
      if (s.status == "fail" && s.failed.empty()) {
        failures += "<li>seed " + std::to_string(s.seed) + ": failed (<a href=\"" + dir +
                    "report.html\">report</a>)</li>";
      }
    }
    h += "<td>" + (failures.empty() ? std::string() : "<ul>" + failures + "</ul>") + "</td></tr>";
  }
  return h + "</table>";
}

// For NEES metrics, the ANEES per grid point against its two-sided 95 % chi-square region, as a
// table and a plot. Returns the number of plots.
int AneesSection(const SweepSpec& spec, const std::vector<std::string>& header,
                 const std::vector<std::vector<std::string>>& rows, const std::string& out_dir,
                 std::string* html) {
  const std::size_t num_params = spec.parameters.size();
  const std::size_t first_metric = num_params + 3;
  int plots = 0;
  // Consistency: the final pose's NEES is independent across seeds, so its mean over a grid
  // point's seeds is an ANEES with a chi-square acceptance region (Bar-Shalom et al. 2001,
  // Sec. 5.4.2). A time-averaged NEES (mean_nees) is not: its samples are correlated in time.
  // A landmark estimator's landmark_anees is a run's mean NEES over its mapped landmarks (2 dof
  // each); weighted by the run's pillars_mapped (a metric of the same configuration, which the
  // sweep must list) it pools into the ANEES over every landmark of every run. The region then
  // treats the landmarks as independent, which they are not quite (they share the pose's error).
  const auto ends_with = [](const std::string& name, const std::string& suffix) {
    return name.size() >= suffix.size() &&
           name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  for (std::size_t m = first_metric; m + 1 < header.size(); ++m) {
    const std::string& name = header[m];
    int dimension = 0;
    std::size_t weight_column = 0;  // 0: one sample per run
    std::string what;
    if (ends_with(name, "final_nees")) {
      dimension = 3;
      what = "pose, 3 dof";
    } else if (ends_with(name, "landmark_anees")) {
      const std::string mapped =
          name.substr(0, name.size() - std::string("landmark_anees").size()) + "pillars_mapped";
      const auto it = std::find(header.begin() + first_metric, header.end(), mapped);
      if (it == header.end()) continue;
      weight_column = static_cast<std::size_t>(it - header.begin());
      dimension = 2;
      what = "landmarks, 2 dof, pooled over the mapped landmarks of all runs";
    } else {
      continue;
    }
    // One group per grid point (the swept values), in results.csv order: (value, weight) pairs.
    std::vector<std::string> labels;
    std::map<std::string, std::vector<std::pair<double, double>>> samples;
    for (const auto& row : rows) {
      if (row.size() != header.size()) continue;
      std::string label;
      for (std::size_t q = 0; q < num_params; ++q)
        label += (label.empty() ? "" : ", ") + spec.parameters[q].key + "=" + row[1 + q];
      if (label.empty()) label = "all runs";
      const double v = CsvNumber(row[m]);
      const double w = weight_column > 0 ? CsvNumber(row[weight_column]) : 1.0;
      if (!std::isfinite(v) || !std::isfinite(w) || !(w > 0.0)) continue;
      if (!samples.count(label)) labels.push_back(label);
      samples[label].emplace_back(v, w);
    }
    if (labels.empty()) continue;
    *html +=
        "<h2>ANEES of " + name + " (" + what +
        ") with the two-sided 95 % chi-square region</h2><table><tr><th>grid "
        "point</th><th>runs</th><th>ANEES</th><th>lower</th><th>upper</th><th>verdict</th></tr>";
    PlotSeries anees, lower, upper;
    anees.label = "ANEES";
    anees.colour = PaletteColour(0);
    anees.markers = true;
    lower.label = "95 % lower";
    upper.label = "95 % upper";
    lower.colour = upper.colour = PaletteColour(1);
    lower.dashed = upper.dashed = true;
    for (std::size_t g = 0; g < labels.size(); ++g) {
      const std::vector<std::pair<double, double>>& v = samples[labels[g]];
      double sum = 0.0, weight = 0.0;
      for (const auto& [x, w] : v) {
        sum += w * x;
        weight += w;
      }
      const double mean = sum / weight;
      const slam::NeesBounds bounds =
          slam::AneesBounds(dimension, static_cast<int>(std::lround(weight)));
      const bool inside = mean >= bounds.lower && mean <= bounds.upper;
      char cells[256];
      std::snprintf(cells, sizeof(cells), "<td>%zu</td><td>%.3f</td><td>%.3f</td><td>%.3f</td>",
                    v.size(), mean, bounds.lower, bounds.upper);
      *html += "<tr><td>" + labels[g] + "</td>" + cells + "<td>" +
               (inside ? "inside"
                       : (mean < bounds.lower ? "below (pessimistic)" : "above (optimistic)")) +
               "</td></tr>";
      // The bounds span [g - 0.4, g + 0.4] round each point, so that one point draws them too.
      anees.x.push_back(static_cast<double>(g));
      anees.y.push_back(mean);
      for (const double x : {static_cast<double>(g) - 0.4, static_cast<double>(g) + 0.4}) {
        lower.x.push_back(x);
        upper.x.push_back(x);
        lower.y.push_back(bounds.lower);
        upper.y.push_back(bounds.upper);
      }
    }
    *html += "</table>";
    PlotOptions options;
    options.title = "ANEES of " + name + " per grid point";
    options.x_label = "grid point (table order)";
    options.y_label = "ANEES";
    const std::string file = "summary_anees_" + name + ".png";
    slam::WriteFileAtomically((fs::path(out_dir) / file).string(),
                              RenderLinePlotPng({anees, lower, upper}, options));
    *html += "<img alt=\"ANEES of " + name + "\" src=\"" + file + "\">";
    ++plots;
  }
  return plots;
}

}  // namespace

std::string JoinCsv(const std::vector<std::string>& fields) {
  std::string line;
  for (std::size_t i = 0; i < fields.size(); ++i) line += (i ? "," : "") + CsvField(fields[i]);
  return line;
}

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

double CsvNumber(const std::string& s) {
  if (s.empty()) return std::nan("");
  try {
    std::size_t used = 0;
    const double v = std::stod(s, &used);
    return used == s.size() ? v : std::nan("");
  } catch (const std::exception&) {
    return std::nan("");
  }
}

std::string RunDir(const std::string& out_dir, std::size_t index) {
  char name[16];
  std::snprintf(name, sizeof(name), "%04zu", index);
  return (fs::path(out_dir) / "runs" / name).string();
}

SweepAggregate AggregateSweep(
    const SweepSpec& spec, const std::vector<std::string>& header,
    const std::vector<std::vector<std::string>>& rows,
    const std::map<std::size_t, std::vector<ExpectationResult>>& expectations) {
  SweepAggregate a;
  const std::size_t num_params = spec.parameters.size();
  for (std::size_t p = 0; p < num_params; ++p) {
    if (spec.parameters[p].values.size() > 1) a.swept.push_back(p);
  }
  const std::size_t first_metric = num_params + 3;  // run, parameters, seed, status
  for (std::size_t m = first_metric; m + 1 < header.size(); ++m) a.metrics.push_back(header[m]);
  // Every grid point, every seed not run until a row says otherwise.
  std::vector<std::size_t> index(num_params, 0);
  do {
    GridPoint point;
    point.value_index = index;
    for (const std::uint64_t seed : spec.seeds) {
      point.seeds.push_back(
          {seed, a.points.size() * spec.seeds.size() + point.seeds.size(), "", {}});
    }
    a.points.push_back(std::move(point));
  } while (NextGridPoint(spec, &index));
  std::map<std::size_t, std::vector<std::vector<double>>> samples;  // point -> metric -> values
  for (const auto& row : rows) {
    if (row.size() != header.size() || header.size() < first_metric + 1) continue;
    std::size_t point = 0;
    bool known = true;
    for (std::size_t p = 0; p < num_params && known; ++p) {
      const auto& values = spec.parameters[p].values;
      const auto v = std::find(values.begin(), values.end(), row[1 + p]);
      known = v != values.end();
      point = point * values.size() + static_cast<std::size_t>(v - values.begin());
    }
    const auto seed = std::find_if(spec.seeds.begin(), spec.seeds.end(), [&](std::uint64_t s) {
      return std::to_string(s) == row[1 + num_params];
    });
    if (!known || seed == spec.seeds.end()) continue;
    SeedResult& s = a.points[point].seeds[static_cast<std::size_t>(seed - spec.seeds.begin())];
    s.status = row[2 + num_params];
    const auto e = expectations.find(s.run_index);
    if (s.status == "fail" && e != expectations.end()) {
      for (const ExpectationResult& r : e->second) {
        if (!r.passed) s.failed.push_back(r);
      }
    }
    auto& values = samples[point];
    values.resize(a.metrics.size());
    for (std::size_t m = 0; m < a.metrics.size(); ++m) {
      const double v = CsvNumber(row[first_metric + m]);
      if (std::isfinite(v)) values[m].push_back(v);
    }
  }
  for (const auto& [point, values] : samples) {
    for (std::size_t m = 0; m < values.size(); ++m) {
      if (values[m].empty()) continue;
      MetricStats stats;
      stats.count = static_cast<int>(values[m].size());
      double sum = 0.0;
      stats.min = stats.max = values[m].front();
      for (const double v : values[m]) {
        sum += v;
        stats.min = std::min(stats.min, v);
        stats.max = std::max(stats.max, v);
      }
      stats.mean = sum / stats.count;
      a.points[point].metrics[a.metrics[m]] = stats;
    }
  }
  for (const GridPoint& point : a.points) {
    for (const SeedResult& s : point.seeds) {
      a.passed += s.status == "pass";
      a.failed += s.status == "fail";
      a.errors += s.status == "error";
      a.missing += s.status.empty();
    }
  }
  return a;
}

std::vector<ExpectationResult> ReadRunExpectations(const std::string& metrics_json) {
  std::vector<ExpectationResult> out;
  std::error_code error;
  if (!fs::exists(metrics_json, error)) return out;
  try {
    const YAML::Node root = YAML::LoadFile(metrics_json);
    for (const auto& e : root["expectations"]) {
      ExpectationResult r;
      r.name = e.first.as<std::string>();
      // JsonWriter writes a NaN (a metric that could not be computed) as null.
      r.value = e.second["value"].IsNull() ? std::nan("") : e.second["value"].as<double>();
      r.threshold = e.second["threshold"].as<double>();
      r.passed = e.second["passed"].as<bool>();
      out.push_back(r);
    }
  } catch (const YAML::Exception&) {
    out.clear();  // unreadable: the table says the run failed and links its report
  }
  return out;
}

int WriteSweepSummary(const SweepSpec& spec, const std::string& out_dir) {
  std::ifstream in(fs::path(out_dir) / "results.csv");
  std::string line;
  if (!std::getline(in, line)) return 0;
  const std::vector<std::string> header = SplitCsv(line);
  std::vector<std::vector<std::string>> rows;
  while (std::getline(in, line)) {
    if (!line.empty()) rows.push_back(SplitCsv(line));
  }
  const std::size_t status_column = spec.parameters.size() + 2;
  std::map<std::size_t, std::vector<ExpectationResult>> expectations;
  const std::vector<SweepRun> runs = ExpandSweep(spec);
  std::map<std::string, std::size_t> run_of_id;
  for (std::size_t i = 0; i < runs.size(); ++i) run_of_id[runs[i].id] = i;
  for (const auto& row : rows) {
    if (row.size() <= status_column || row[status_column] != "fail") continue;
    const auto run = run_of_id.find(row[0]);
    if (run == run_of_id.end()) continue;
    expectations[run->second] =
        ReadRunExpectations((fs::path(RunDir(out_dir, run->second)) / "metrics.json").string());
  }
  const SweepAggregate a = AggregateSweep(spec, header, rows, expectations);

  std::string swept;
  for (const std::size_t p : a.swept) swept += (swept.empty() ? "" : ", ") + spec.parameters[p].key;
  std::string held;
  for (std::size_t p = 0; p < spec.parameters.size(); ++p) {
    if (spec.parameters[p].values.size() == 1) {
      held += (held.empty() ? "" : ", ") + spec.parameters[p].key + " = " +
              spec.parameters[p].values.front();
    }
  }
  std::string html =
      "<!doctype html><html><head><meta charset=\"utf-8\"><title>sweep summary</title><style>"
      "body{font-family:sans-serif;margin:2em;max-width:70em}img{max-width:100%;border:1px "
      "solid #ddd}table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid "
      "#ccc;padding:4px 8px;text-align:left;vertical-align:top}td.pass{background:#e3f4e1}"
      "td.fail,td.error{background:#fbe0e0;font-weight:bold}td.none{color:#888}"
      "table.heat td{text-align:center}ul{margin:0;padding-left:1.2em}</style></head><body>"
      "<h1>Sweep summary</h1><p>Scenario: " +
      EscapeHtml(spec.scenario_path) + ".</p><p class=\"counts\">" +
      std::to_string(a.passed + a.failed + a.errors + a.missing) +
      " runs: " + std::to_string(a.passed) + " passed, " + std::to_string(a.failed) + " failed, " +
      std::to_string(a.errors) + " ended in an error, " + std::to_string(a.missing) +
      " not run yet.</p><p>Swept: " + EscapeHtml(swept.empty() ? "nothing (seeds only)" : swept) +
      (held.empty() ? "" : "; held: " + EscapeHtml(held)) + ".</p>";
  html += "<h2>Runs</h2>" + RunsTable(spec, a);
  int plots = 0;
  if (a.swept.size() == 2) {
    html += "<h2>Metrics</h2>";
    for (const std::string& metric : a.metrics) html += HeatMap(spec, a, metric);
  } else if (!a.swept.empty()) {
    html += "<h2>Metrics</h2><p>Each point is the mean over seeds, bars the min-max spread.</p>";
    plots += LinePlots(spec, a, out_dir, &html);
  }
  plots += AneesSection(spec, header, rows, out_dir, &html);
  html += "</body></html>\n";
  slam::WriteFileAtomically((fs::path(out_dir) / "summary.html").string(), html);
  return plots;
}

}  // namespace slamrig::scenario
