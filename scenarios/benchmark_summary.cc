#include "scenarios/benchmark_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "scenarios/html.h"
#include "scenarios/plot.h"
#include "scenarios/sweep_summary.h"
#include "slam/io/atomic_file.h"

namespace slamrig::scenario {
namespace {

namespace fs = std::filesystem;

std::string Metres(double v) {
  if (!std::isfinite(v)) return "n/a";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), v < 10.0 ? "%.3f" : "%.1f", v);
  return buffer;
}

std::string RunLink(std::size_t index) {
  char name[64];
  std::snprintf(name, sizeof(name), "runs/%04zu/report.html", index);
  return name;
}

std::string LeaderboardTable(const Leaderboard& board) {
  std::string h = "<table><tr><th>estimator</th><th>silent failures</th><th>failures</th>";
  for (const std::string& d : board.datasets) h += "<th>" + EscapeHtml(d) + "</th>";
  h += "</tr>";
  for (std::size_t e = 0; e < board.estimators.size(); ++e) {
    int runs = 0, failures = 0, silent = 0;
    for (const LeaderboardCell& c : board.cells[e]) {
      runs += c.runs;
      failures += c.failures;
      silent += c.silent;
    }
    h += "<tr><th>" + EscapeHtml(board.estimators[e]) + "</th><td class=\"" +
         (silent > 0 ? "fail" : "pass") + "\">" + std::to_string(silent) + " of " +
         std::to_string(runs) + "</td><td class=\"" + (failures > 0 ? "fail" : "pass") + "\">" +
         std::to_string(failures) + " of " + std::to_string(runs) + "</td>";
    for (const LeaderboardCell& c : board.cells[e]) {
      if (c.runs == 0) {
        h += "<td class=\"none\">not run</td>";
        continue;
      }
      h += std::string("<td class=\"") + (c.failures > 0 ? "fail" : "pass") + "\">" +
           Metres(c.median) + " / " + Metres(c.p90) + " / " + Metres(c.max) + "<br><small>" +
           std::to_string(c.failures) + " of " + std::to_string(c.runs) + " failed</small></td>";
    }
    h += "</tr>";
  }
  return h + "</table>";
}

// Per dataset, each estimator's ATE over its runs in ascending order against the fraction of
// runs: the whole distribution at a glance, the worst runs at the right end.
int QuantilePlots(const Leaderboard& board, const std::string& out_dir, std::string* html) {
  int plots = 0;
  for (std::size_t d = 0; d < board.datasets.size(); ++d) {
    std::vector<PlotSeries> series;
    for (std::size_t e = 0; e < board.estimators.size(); ++e) {
      const LeaderboardCell& c = board.cells[e][d];
      if (c.ate.empty()) continue;
      PlotSeries s;
      s.label = board.estimators[e];
      s.colour = PaletteColour(e);
      s.markers = c.ate.size() <= 30;
      for (std::size_t i = 0; i < c.ate.size(); ++i) {
        s.x.push_back(c.ate.size() == 1
                          ? 1.0
                          : static_cast<double>(i) / static_cast<double>(c.ate.size() - 1));
        s.y.push_back(c.ate[i]);
      }
      series.push_back(std::move(s));
    }
    if (series.empty()) continue;
    PlotOptions options;
    options.title = board.datasets[d] + ": ATE RMSE over runs, sorted";
    options.x_label = "fraction of runs";
    options.y_label = "ATE RMSE (m)";
    const std::string file = "summary_ate_" + board.datasets[d] + ".png";
    slam::WriteFileAtomically((fs::path(out_dir) / file).string(),
                              RenderLinePlotPng(series, options));
    *html += "<h3>" + EscapeHtml(board.datasets[d]) + "</h3><img alt=\"" +
             EscapeHtml(options.title) + "\" src=\"" + EscapeHtml(file) + "\">";
    ++plots;
  }
  return plots;
}

std::string WorstTable(const Leaderboard& board) {
  std::string h =
      "<table><tr><th>run</th><th>status</th><th>ATE RMSE (m)</th><th>diverged (its own "
      "verdict)</th><th>lost (s)</th><th>why</th></tr>";
  for (const BenchmarkCase& c : board.worst) {
    h += "<tr><td><a href=\"" + RunLink(c.run_index) + "\">" + EscapeHtml(c.id) +
         "</a></td><td class=\"" + (c.status == "pass" ? "pass" : "fail") + "\">" +
         EscapeHtml(c.status) + "</td><td>" + Metres(c.ate_rmse_m) + "</td><td>" +
         (c.diverged.empty()  ? "&ndash;"
          : c.diverged == "1" ? "yes"
                              : "no") +
         "</td><td>" + EscapeHtml(c.lost_s) + "</td><td>" + EscapeHtml(c.failure) + "</td></tr>";
  }
  return h + "</table>";
}

}  // namespace

double Quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const double position = q * static_cast<double>(sorted.size() - 1);
  const std::size_t below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, sorted.size() - 1);
  const double t = position - static_cast<double>(below);
  return sorted[below] + t * (sorted[above] - sorted[below]);
}

Leaderboard BuildLeaderboard(const BenchmarkSuite& suite, const std::vector<std::string>& header,
                             const std::vector<std::vector<std::string>>& rows) {
  Leaderboard board;
  for (const BenchmarkEstimator& e : suite.estimators) board.estimators.push_back(e.name);
  for (const BenchmarkDataset& d : suite.datasets) board.datasets.push_back(d.name);
  board.cells.assign(board.estimators.size(), std::vector<LeaderboardCell>(board.datasets.size()));
  auto column = [&header](const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  const std::size_t id_col = column("run"), status_col = column("status"),
                    failure_col = column("failure"), ate_col = column("ate_rmse_m"),
                    diverged_col = column("diverged"), lost_col = column("lost_s");
  const std::vector<BenchmarkRun> runs = ExpandBenchmark(suite);
  std::map<std::string, std::size_t> index_of;
  for (std::size_t i = 0; i < runs.size(); ++i) index_of[runs[i].id] = i;
  std::vector<BenchmarkCase> cases;
  for (const std::vector<std::string>& row : rows) {
    if (row.size() != header.size() || ate_col >= header.size()) continue;
    const auto found = index_of.find(row[id_col]);
    if (found == index_of.end()) continue;
    const BenchmarkRun& run = runs[found->second];
    LeaderboardCell& cell = board.cells[run.estimator][run.dataset];
    ++cell.runs;
    BenchmarkCase c{found->second,
                    row[id_col],
                    row[status_col],
                    row[failure_col],
                    CsvNumber(row[ate_col]),
                    diverged_col < header.size() ? row[diverged_col] : "",
                    lost_col < header.size() ? row[lost_col] : ""};
    if (c.status != "pass") {
      ++cell.failures;
      if (diverged_col >= header.size() || row[diverged_col] != "1") ++cell.silent;
    }
    if (std::isfinite(c.ate_rmse_m)) cell.ate.push_back(c.ate_rmse_m);
    cases.push_back(std::move(c));
  }
  board.missing = static_cast<int>(runs.size() - cases.size());
  for (auto& per_estimator : board.cells) {
    for (LeaderboardCell& cell : per_estimator) {
      std::sort(cell.ate.begin(), cell.ate.end());
      cell.median = Quantile(cell.ate, 0.5);
      cell.p90 = Quantile(cell.ate, 0.9);
      cell.max = cell.ate.empty() ? 0.0 : cell.ate.back();
    }
  }
  // Failures first, then the largest ATE; ties in suite order.
  std::stable_sort(cases.begin(), cases.end(), [](const BenchmarkCase& a, const BenchmarkCase& b) {
    const bool fa = a.status != "pass", fb = b.status != "pass";
    if (fa != fb) return fa;
    const double ea = std::isfinite(a.ate_rmse_m) ? a.ate_rmse_m : INFINITY;
    const double eb = std::isfinite(b.ate_rmse_m) ? b.ate_rmse_m : INFINITY;
    return ea > eb;
  });
  constexpr std::size_t kWorst = 10;
  cases.resize(std::min(cases.size(), kWorst));
  board.worst = std::move(cases);
  return board;
}

void WriteBenchmarkSummary(const BenchmarkSuite& suite, const std::string& out_dir) {
  std::ifstream in(fs::path(out_dir) / "results.csv");
  std::string line;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  if (std::getline(in, line)) header = SplitCsv(line);
  while (std::getline(in, line)) {
    if (!line.empty()) rows.push_back(SplitCsv(line));
  }
  const Leaderboard board = BuildLeaderboard(suite, header, rows);
  std::string html =
      "<!doctype html><html><head><meta charset=\"utf-8\"><title>benchmark summary</title><style>"
      "body{font-family:sans-serif;margin:2em;max-width:80em}img{max-width:100%;border:1px "
      "solid #ddd}table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid "
      "#ccc;padding:4px 8px;text-align:left;vertical-align:top}td.pass{background:#e3f4e1}"
      "td.fail{background:#fbe0e0}td.none{color:#888}</style></head><body>"
      "<h1>Benchmark summary</h1><p>Suite: " +
      EscapeHtml(suite.path) + "; " + std::to_string(rows.size()) + " runs recorded" +
      (board.missing > 0 ? ", " + std::to_string(board.missing) + " not run yet" : "") +
      ".</p><h2>Leaderboard</h2><p>ATE RMSE in metres over each dataset's runs: median / 90th "
      "percentile / maximum. A run fails when it crashes, times out (" +
      Metres(suite.timeout_s) + " s), ends in an error, or its ATE is above " +
      Metres(suite.fail_above_m) + " m (the suite's <code>fail_above_m</code>).</p>" +
      LeaderboardTable(board) + "<h2>Distributions</h2>";
  QuantilePlots(board, out_dir, &html);
  html +=
      "<h2>Worst cases</h2>" + WorstTable(board) +
      "<p>Every run: <a href=\"results.csv\">results.csv</a>; each run's scenario is "
      "runs/&lt;n&gt;/scenario.yaml (<code>slamrig run</code> runs it again).</p></body></html>\n";
  slam::WriteFileAtomically((fs::path(out_dir) / "summary.html").string(), html);
}

}  // namespace slamrig::scenario
