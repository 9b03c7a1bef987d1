// What `jointguard diagnose` reports of a diagnosis run (diagnosis/run_diagnosis.hpp): the
// console summary, the contract JSON (--json), the SVG plots per joint (--out) and the robot
// file written back (--model-out).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "diagnosis/run_diagnosis.hpp"

namespace jg::cli {

/// Where the diagnosis goes besides the console; an empty path: not written.
struct DiagnoseOutputs {
  std::string json;              ///< the findings (contract format)
  std::string plots;             ///< folder for the SVG plots (created when missing)
  std::string model_out;         ///< the robot file with what was found
  std::string model_out_header;  ///< the comment on top of that file (how it was written)
};

/// Prints the summary as the run goes (stage() as diag::DiagnosisSettings::on_stage) and
/// writes the outputs asked for at its end (finish(); the robot file needs
/// DiagnosisResult::model_out).
class DiagnosisWriter {
 public:
  /// `in` must outlive the writer.
  DiagnosisWriter(const diag::DiagnosisInputs& in, DiagnoseOutputs out);
  void stage(diag::DiagnosisStage stage, const diag::DiagnosisResult& r);
  void finish(const diag::DiagnosisResult& r);

 private:
  const diag::DiagnosisInputs& in_;
  DiagnoseOutputs out_;
  nlohmann::json j_;  ///< the contract JSON, filled stage by stage
};

}  // namespace jg::cli
