#include "push_methods.h"

#include "cps/parameters.h"

namespace cli_test {

std::vector<std::string> push_method_names() {
  std::vector<std::string> names;
  for (const cps::Choice& c : cps::parameter("push").choices) names.emplace_back(c.name);
  return names;
}

std::vector<Reads> push_method_reads() {
  std::vector<Reads> reads;
  for (const cps::Choice& c : cps::parameter("push").choices) {
    const cps::PushReads r = cps::push_reads(static_cast<cps::PushMode>(c.value));
    reads.push_back({r.solver, r.friction_model, r.warm_start});
  }
  return reads;
}

int push_methods() { return static_cast<int>(cps::parameter("push").choices.size()); }

int paper_push_methods() {
  int n = 0;
  for (const cps::Choice& c : cps::parameter("push").choices) n += c.in_paper;
  return n;
}

}  // namespace cli_test
