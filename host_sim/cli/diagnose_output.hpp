// What `jointguard diagnose` reports of a diagnosis run (diagnosis/run_diagnosis.hpp): the
// console summary, the contract JSON (--json), the SVG plots per joint (--out) and the robot
// file written back (--model-out).
#pragma once

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

/// Prints the summary and writes the outputs asked for (the robot file needs
/// DiagnosisResult::model_out).
void write_diagnosis(const diag::DiagnosisInputs& in, const diag::DiagnosisResult& r, const DiagnoseOutputs& out);

}  // namespace jg::cli
