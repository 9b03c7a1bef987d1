// The concealed-effect benchmark: N random cases (seeded), the share named correctly,
// false claims on matched pairs, and held-out residual against the noise floor.
// Usage: jg_diagnosis_testset [--jobs N] [count] [seed] [effect,effect,...]  (the optional
// list keeps only the drawn cases of those effects, e.g. to study one effect; "none" =
// matched pairs). --jobs N (default 0: every core): the cases are independent (each seeded
// from its own draw), run over N threads into their own slots and printed in case order, so
// the output does not depend on N. --generator second: the second, independent generator
// (testset_second.hpp: the same causes in other shapes than the diagnosis fits); its
// matched pairs are "matched" or "matched:<shape>" (a shape known to both recordings).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "diagnosis/testset.hpp"
#include "diagnosis/testset_second.hpp"
#include "eval/parallel.hpp"

int main(int argc, char** argv) {
  int jobs = 0;
  std::string generator = "first";
  std::vector<const char*> args;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--jobs") == 0 && i + 1 < argc) {
      jobs = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--generator") == 0 && i + 1 < argc) {
      generator = argv[++i];
    } else {
      args.push_back(argv[i]);
    }
  }
  if (jobs < 0) {
    std::fprintf(stderr, "jg_diagnosis_testset: --jobs must be >= 0\n");
    return 2;
  }
  if (generator != "first" && generator != "second") {
    std::fprintf(stderr, "jg_diagnosis_testset: --generator must be first or second\n");
    return 2;
  }
  const bool second = generator == "second";
  if (jobs == 0) jobs = jg::eval::default_jobs();
  const int count = !args.empty() ? std::atoi(args[0]) : 60;
  const unsigned long long seed = args.size() > 1 ? std::strtoull(args[1], nullptr, 10) : 1;
  const auto arm = jg::diag::default_test_arm();
  const auto drawn = second ? jg::diag::draw_cases_second(count, seed, 0.17, 3) : jg::diag::draw_cases(count, seed, 0.17, 3);
  const std::string only = args.size() > 2 ? std::string(",") + args[2] + "," : std::string();
  std::vector<jg::diag::ConcealedCase> cases;
  for (const auto& c : drawn) {
    if (only.empty() || only.find("," + c.effect + ",") != std::string::npos) cases.push_back(c);
  }
  std::vector<jg::diag::CaseOutcome> outcomes(cases.size());
  // The bench's own switches (environment): what each case prints while it runs.
  jg::diag::CaseTrace trace;
  trace.non_finite = std::getenv("JG_DIAG_TRACE") != nullptr;
  trace.selection = std::getenv("JG_DIAG_TRACE_SELECTION") != nullptr;
  jg::eval::parallel_for(cases.size(), jobs, [&](std::size_t i) {
    const auto& c = cases[i];
    if (trace.non_finite) std::fprintf(stderr, "running %s joint %d %s A=%.3f seed %llu\n", jg::robot::effect_cstr(c.effect), c.joint, c.concealment.c_str(), c.amplitude_nm, c.seed);
    outcomes[i] = second ? jg::diag::run_case_second(c, arm, trace) : jg::diag::run_case(c, arm, trace);
  });
  int effect_cases = 0, named = 0, matched = 0, false_claims = 0, floor_ok = 0, floor_n = 0, resim_ok = 0;
  std::map<std::string, std::pair<int, int>> per_effect;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto& c = cases[i];
    const auto& o = outcomes[i];
    std::string found;
    for (const auto& f : o.arm.findings) found += "arm:" + f.effect + " ";
    if (std::getenv("JG_DIAG_TRACE")) {
      for (const auto& note : o.arm.notes) std::fprintf(stderr, "  arm note: %s\n", note.c_str());
      for (const auto& j : o.joints)
        for (const auto& note : j.notes) std::fprintf(stderr, "  joint %d note: %s\n", j.joint, note.c_str());
      for (const auto& a : o.resim_applied) std::fprintf(stderr, "  model-out: %s\n", a.c_str());
      for (const auto& a : o.resim_not_modelled) std::fprintf(stderr, "  model-out, not modelled: %s\n", a.c_str());
    }
    for (const auto& j : o.joints)
      for (const auto& f : j.findings) found += "j" + std::to_string(j.joint) + ":" + f.effect + " ";
    std::printf("%-24s joint %d %-13s A=%.3f held-out %.3f -> %.3f (noise %.3f), re-simulated %.3f (noise %.3f)%s -> %s%s\n",
                jg::robot::effect_cstr(c.effect), c.joint, c.concealment.c_str(), c.amplitude_nm, o.heldout_before, o.heldout_after, o.noise,
                o.resim_heldout, o.resim_noise, jg::diag::resim_at_noise_floor(o) ? "" : " NOT AT FLOOR",
                found.empty() ? "none" : found.c_str(), c.effect == jg::robot::Effect::none ? (o.false_claim ? "  FALSE CLAIM" : "  ok") : (o.named ? "  ok" : "  MISSED"));
    if (c.effect == jg::robot::Effect::none) {
      ++matched;
      false_claims += o.false_claim ? 1 : 0;
    } else {
      ++effect_cases;
      named += o.named ? 1 : 0;
      auto& pe = per_effect[jg::robot::effect_word(c.effect)];  // by name: the table prints in its order
      pe.second++;
      pe.first += o.named ? 1 : 0;
      ++floor_n;
      floor_ok += jg::diag::at_noise_floor(o) ? 1 : 0;
      resim_ok += jg::diag::resim_at_noise_floor(o) ? 1 : 0;
    }
  }
  std::printf("\nnamed correctly: %d / %d (%.0f %%); matched pairs with a claim: %d / %d; held-out RMS at the noise floor (within 10 %% of the noise, or >= 2x lower where the effect is >= 3x the noise): %d / %d\n",
              named, effect_cases, 100.0 * named / std::max(1, effect_cases), false_claims, matched, floor_ok, floor_n);
  std::printf("re-simulated with the findings written back (model_out.hpp): held-out RMS against the real recording at the noise floor: %d / %d (%.0f %%)\n",
              resim_ok, floor_n, 100.0 * resim_ok / std::max(1, floor_n));
  for (const auto& [e, v] : per_effect) {
    std::printf("  %-24s %d / %d", e.c_str(), v.first, v.second);
    if (second) std::printf("   (%s)", jg::diag::second_shape_description(*jg::robot::parse_effect(e)).c_str());
    std::printf("\n");
  }
  return 0;
}
