// The second, independent concealed-effect generator (issue 30 item 6). The first set
// (testset.hpp) hides each effect in the shape the diagnosis looks for, so its figure is
// partly circular. This one hides the same causes in other physically sensible shapes
// (docs/diagnosis.md, "A second, independent generator"): a payload that is a rigid body,
// a Stribeck curve that differs by direction, a fractional delay, a two-stage warm-up, a
// hardening gear... Each case is scored like the first set's: the vocabulary word a user
// would expect named on the effect's joint (at the arm level for payload and
// link_inertial_error), and nothing claimed on a matched pair.
#pragma once

#include <string>
#include <vector>

#include "diagnosis/testset.hpp"

namespace jg::diag {

/// Cases of the second generator: effect, joint, amplitude (the RMS of the effect's torque
/// over the reference motion where the shape allows, see the docs' table), concealment
/// (low_amplitude, plain, mixed; matched pairs "matched:<shape>" carry a second shape in
/// both recordings, or "matched" for none) and seed, drawn from a stream of their own.
std::vector<ConcealedCase> draw_cases_second(int count, unsigned long long seed, double noise_rms_nm, int joints);

/// Simulates the pair with the second shape of the case's effect and diagnoses it
/// (diagnose_pair: the same scoring as run_case).
CaseOutcome run_case_second(const ConcealedCase& c, const TestArm& arm, const CaseTrace& trace = {});

/// One line per effect: the second shape, for the bench's printout and the docs' table.
std::string second_shape_description(robot::Effect effect);

}  // namespace jg::diag
