// The pipeline's HTML page (jointguard pipeline, report.html): the command's identity, the
// friction identified, the thresholds, and per recording its detections (with the contact
// estimate as report/contact_report.hpp states it) and a plot of the estimate with them.
#pragma once

#include <string>

#include "workflow/pipeline_run.hpp"

namespace jg::workflow {

std::string pipeline_report_html(const PipelineOptions& o, const PipelineResult& r);

}  // namespace jg::workflow
