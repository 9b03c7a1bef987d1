// A recording's CSV text with only its torque (or current) columns rewritten: every other
// field keeps its text byte for byte (header, order, extra columns, spacing, line ends).
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace jg::inject {

/// The new reading of each torque column (joint order) for one data row, from the row's
/// time [s] and its old readings (column units). Returns false for a row to leave as it is
/// (outside every segment the added torque was computed on).
using RowRule = std::function<bool(double t_s, const std::vector<double>& old_values, std::vector<double>& new_values)>;

struct EditedCsv {
  std::string text;
  std::vector<std::string> columns;        ///< the torque columns, joint order
  std::size_t data_rows = 0;
  std::size_t rows_outside = 0;            ///< rows the rule left as they are
  std::vector<std::size_t> rows_changed;   ///< per joint
  std::vector<double> max_abs_change;      ///< per joint [column units]
  std::vector<double> rms_change;          ///< per joint, over the rows changed [column units]
};

/// Rewrites the columns `<prefix><j>` (j = joint_ids; "q01" style numbering as the reader
/// takes it) of `text` (the file `path`, for messages). `same_state_repeats`: a row whose
/// q, dq and torque/current readings all equal the previous row's is the logger repeating a
/// state (io/regularize.hpp drops it): it gets the previous row's new text, so it stays a
/// repeat. A value that is not finite is refused (io::FormatError: file, line, field).
EditedCsv edit_torque_columns(const std::string& text, const std::string& path, const std::vector<int>& joint_ids,
                              const std::string& prefix, bool same_state_repeats, const RowRule& rule);

/// `value` printed for the field `source` replaces: "%.*g" with 9 significant digits
/// (5e-10 relative: far below any torque or current sensor's resolution), or as many as the
/// source had when it had more (never coarser than the file).
std::string format_like(double value, const std::string& source);

/// Whether a header has a column `<prefix><j>` for one of the joints.
bool has_joint_column(const std::string& header_line, const std::vector<int>& joint_ids, const std::string& prefix);

}  // namespace jg::inject
