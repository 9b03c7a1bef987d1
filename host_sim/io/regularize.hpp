// Recordings as real loggers write them, made uniform: jittered time stamps, rows that
// repeat the previous state, skipped samples and short gaps are resampled onto a uniform
// grid by linear interpolation on the time stamp; long gaps split the recording into
// segments that tools run one at a time (each from a fresh state).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "io/recording.hpp"

namespace jg::io {

struct RegularizeOptions {
  /// Output rate [Hz]; 0 = 1 / (median step between rows that carry a new state),
  /// rounded to the nearest usual rate (1, 1.25, 2, 2.5, 4, 5, 8 x 10^k Hz) within 2 %,
  /// else to 3 significant digits (1.000 ms -> 1000 Hz, 10 ms -> 100 Hz).
  double rate_hz = 0.0;
  /// A step longer than gap_steps median steps and longer than gap_min_s splits the
  /// recording: too long to interpolate over (a stop, a lost connection).
  double gap_steps = 10.0;
  double gap_min_s = 0.02;
  /// When > 0, the split threshold itself [s] (replaces the two above).
  double max_gap_s = 0.0;
  /// Segments with fewer resampled samples than this are dropped (and reported).
  std::size_t min_segment_samples = 3;
  /// Rows whose q, dq and torque/current all equal the previous row's are a logger
  /// reading the same state twice: their time stamp is not the state's. Dropped, except
  /// that a run longer than hold_steps median steps is a state really held (an arm at
  /// rest with quantised sensors): its last row is kept so the value holds until then.
  bool drop_repeats = true;
  double hold_steps = 5.0;
  /// Refuse to produce more than this many samples (a typo in --rate must not take GBs).
  std::size_t max_samples = 20'000'000;
};

struct SegmentSpan {
  double t_begin = 0.0, t_end = 0.0;  ///< [s] on the recording's clock
  std::size_t rows_in = 0;             ///< rows of the file in it (repeats included)
  std::size_t samples = 0;             ///< samples after resampling
};

struct RegularizeReport {
  std::string source;              ///< file name (for messages)
  std::string method;              ///< "linear by time stamp" or "none (uniform)"
  double rate_hz = 0.0;            ///< output rate [Hz]
  double step_s = 0.0;             ///< output step [s]
  bool rate_given = false;         ///< rate from the user, not from the data
  double median_step_in_s = 0.0;   ///< median step of the rows carrying a new state [s]
  double min_step_in_s = 0.0, max_step_in_s = 0.0;  ///< over all rows [s]
  double split_gap_s = 0.0;        ///< steps longer than this split [s]
  std::size_t rows_in = 0;         ///< data rows in the file
  std::size_t rows_out = 0;        ///< samples over all kept segments
  std::size_t repeats_dropped = 0; ///< repeated rows not used (reader's exact duplicates included)
  std::size_t gaps_bridged = 0;    ///< steps > 1.5 median steps interpolated over
  double longest_bridged_gap_s = 0.0;
  std::size_t gaps_split = 0;      ///< steps that split the recording
  std::vector<SegmentSpan> segments;  ///< kept, in time order
  std::vector<SegmentSpan> dropped;   ///< too short to use

  /// One line for the user, e.g. "resampled a.csv: 20544 rows -> 20999 at 1000 Hz, ...".
  [[nodiscard]] std::string summary() const;
  /// Index of the longest kept segment.
  [[nodiscard]] std::size_t longest() const;
};

struct Regularized {
  std::vector<Recording> segments;  ///< uniform, each at report.rate_hz
  RegularizeReport report;
};

/// Uniform segments of a recording. A recording that is already uniform (steps within
/// 1 % of each other, no repeats, no split) at the requested rate is returned unchanged.
/// Throws FormatError naming the source and field 't' when no segment is long enough.
[[nodiscard]] Regularized regularize(const Recording& rec, const RegularizeOptions& options = {},
                                     const std::string& source = "recording");

}  // namespace jg::io
