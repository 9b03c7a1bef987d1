// What `jointguard evaluate` reports, built from the runs in index order: the contract JSON,
// the printed table, and the partial JSON of one shard (`--shard K/N`), which
// `jointguard merge` combines into exactly the JSON of one run.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/experiments.hpp"

namespace jg::cli {

struct EvaluateFigures {
  std::vector<eval::RunResult> runs;           ///< index order
  std::vector<eval::FreeRunSegment> free_run;  ///< index order
  double free_run_s = 0.0;                     ///< the whole free run [s]
  nlohmann::json config;  ///< the summary's configuration fields (thresholds, rate, gains, ...)
  nlohmann::json extra = nlohmann::json::object();  ///< further top-level fields (e.g. "safety")
  nlohmann::json identity;  ///< what made the figures (merge: the parts' identity; null otherwise)
};

/// The contact estimate of a run (link, point, force with their spread) and the truth beside
/// it (`runs[i].contact_estimate` of evaluate and of the bus runs).
nlohmann::json contact_json(const eval::ContactOutcome& c);

/// The contract JSON (../shared/CONTRACT.md, `evaluate`).
nlohmann::json evaluate_json(const EvaluateFigures& f);
/// The table and figures on stdout.
void print_figures(const EvaluateFigures& f);
/// Each false alarm of the collision-free run at its first cycle: the joints that flagged,
/// through which detector (band, residual, hold), and every joint's posture, velocity,
/// estimate and moving band, so that its cause can be found without a rerun.
void print_false_alarms(const std::vector<eval::FreeRunSegment>& segments);

/// One shard's part: its runs and segments with their indices, the totals every shard must
/// add up to, and the configuration (equal in every part of one campaign).
nlohmann::json partial_json(const EvaluateFigures& f, int shard, int shards, std::size_t runs_total,
                            std::size_t segments_total, const nlohmann::json& identity);
/// Reads and checks the parts (one per shard, same campaign, nothing missing or twice);
/// throws std::invalid_argument naming the file and what is wrong.
EvaluateFigures merge_partials(const std::vector<std::string>& paths);

/// "K/N" with 1 <= K <= N <= 100000; throws std::invalid_argument otherwise.
void parse_shard(const std::string& text, int& shard, int& shards);

}  // namespace jg::cli
