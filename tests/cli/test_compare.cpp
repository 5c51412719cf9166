// --compare and --overlay, in-process: which parameter, which values, the labels, the errors,
// the grid, the output names (demos/cps/compare.h).
#include "options/compare.h"
#include "options/options.h"

#include <catch2/catch.hpp>

#include <set>
#include <string>

using namespace cps;
using namespace cps::cli;

namespace {

// The message of the UsageError compare_variants throws, or "" if it throws none.
std::string usage_error(const std::string& spec, const scenes::Overrides& base = {}) {
  try {
    compare_variants(spec, base);
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("compare takes every world parameter that has an option, from the table", "[compare]") {
  const std::vector<std::string> names = comparable_options();
  const std::set<std::string> set(names.begin(), names.end());
  for (const Parameter& p : world_parameters()) {
    INFO(p.name);
    CHECK(set.count(std::string(p.flag)) == (p.flag.empty() ? 0u : 1u));
  }
  for (const char* n : {"push", "solver", "beta", "dt", "iterations", "friction", "restitution",
                        "friction-model", "rotation", "contact-margin", "warm-start"}) {
    CHECK(set.count(n) == 1);
  }
}

TEST_CASE("compare beta=V1,V2,V3 gives one variant per value in order, labelled with the paper's name",
          "[compare]") {
  const std::vector<Variant> v = compare_variants("beta=0.05,0.2,0.5", {});
  REQUIRE(v.size() == 3);
  const double expected[] = {0.05, 0.2, 0.5};
  for (std::size_t k = 0; k < 3; ++k) {
    const ParameterValue* value = v[k].overrides.find("beta");
    REQUIRE(value != nullptr);
    CHECK(std::get<double>(*value) == expected[k]);
    CHECK(contains(v[k].label, "push factor constant beta (Eq. 5.2.3)"));
  }
  CHECK(v[0].legend == "beta = 0.05");
  CHECK(contains(v[2].label, "beta = 0.5"));
  // The unit follows the value; a fraction is read for a time and shown to 6 digits.
  const std::vector<Variant> dt = compare_variants("dt=1/60,0.01", {});
  REQUIRE(dt.size() == 2);
  CHECK(std::get<double>(*dt[0].overrides.find("dt")) == 1.0 / 60.0);
  CHECK(dt[0].legend == "dt = 0.0166667 s");
  CHECK(dt[1].legend == "dt = 0.01 s");
  const std::vector<Variant> it = compare_variants("iterations=5,25,100", {});
  REQUIRE(it.size() == 3);
  CHECK(std::get<int>(*it[2].overrides.find("iterations")) == 100);
  CHECK(it[1].legend == "iterations = 25");
  // Values that read alike to 6 digits are shown exactly, so no two labels are equal.
  const std::vector<Variant> close = compare_variants("beta=0.1,0.10000001", {});
  CHECK(close[0].legend != close[1].legend);
}

TEST_CASE("compare push gives every choice and push=V1,V2 the ones listed, with the paper's names",
          "[compare]") {
  scenes::Overrides base;
  base.set("beta", 0.3);
  const std::vector<Variant> all = compare_variants("push", base);
  // Every push method of the parameter table, in its order.
  const auto choices = parameter("push").choices;
  REQUIRE(all.size() == choices.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    CHECK(std::get<int>(*all[i].overrides.find("push")) == choices[i].value);
  }
  CHECK(std::get<int>(*all[0].overrides.find("push")) == static_cast<int>(PushMode::baumgarte));
  CHECK(std::get<int>(*all[1].overrides.find("push")) == static_cast<int>(PushMode::split));
  CHECK(std::get<double>(*all[1].overrides.find("beta")) == 0.3);  // the base stays
  CHECK(contains(all[0].label, "push factor (Sec. 5.3)"));
  CHECK(contains(all[1].label, "single frame push factor (Sec. 8.1)"));
  CHECK(contains(all[1].label, "push = split"));
  const std::vector<Variant> listed = compare_variants("solver=jacobi,pgs", {});
  REQUIRE(listed.size() == 2);
  CHECK(std::get<int>(*listed[0].overrides.find("solver")) == static_cast<int>(SolverKind::jacobi));
  CHECK(contains(listed[0].legend, "projected Jacobi (Sec. 7.1)"));
  // No comparison: one variant, the base, unlabelled.
  const std::vector<Variant> none = compare_variants("", base);
  REQUIRE(none.size() == 1);
  CHECK(none[0].label.empty());
  CHECK(none[0].overrides.values.size() == 1);
}

TEST_CASE("a bad compare spec is a usage error naming the parameter, the value and what is allowed",
          "[compare]") {
  scenes::Overrides beta;
  beta.set("beta", 0.3);
  struct Case {
    std::string spec;
    std::vector<std::string> says;
  };
  const Case cases[] = {
      {"nosuch=1,2", {"'nosuch'", "beta", "push"}},
      {"gravity=0,0", {"'gravity'"}},                       // no option: not comparable
      {"beta=0.05,2", {"--beta 2", "[0, 1]"}},             // out of range
      {"beta=0.05,abc", {"abc", "not a number"}},
      {"iterations=5,2.5", {"2.5", "whole number"}},
      {"push=baumgarte,sideways", {"sideways", "baumgarte, split"}},
      {"beta=0.1", {"1 value", "2 to 8"}},
      {"beta=0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9", {"more than 8", "2 to 8"}},
      {"beta=0.5,0.50", {"'0.50'", "same value", "'0.5'"}},
      {"push=split,split", {"same value"}},
      {"beta=0.1,,0.2", {"value 2 is empty"}},
      {"beta=", {"1 value"}},
      {"beta", {"give the values of beta", "[0, 1]"}},       // a number needs its values
      {"dt=0,1/60", {"--dt 0", "[1e-06, 1]"}},
  };
  for (const Case& c : cases) {
    INFO("--compare " << c.spec);
    const std::string why = usage_error(c.spec);
    CHECK(contains(why, "--compare " + c.spec + ":"));
    for (const std::string& s : c.says) CHECK(contains(why, s));
  }
  // A parameter set by its own option as well.
  CHECK(contains(usage_error("beta=0.1,0.2", beta), "--beta is given too"));
  scenes::Overrides push;
  push.set("push", PushMode::split);
  CHECK(contains(usage_error("push", push), "--push is given too"));
  // A setting the given push does not read (cps::push_reads): every variant the same run.
  scenes::Overrides avbd;
  avbd.set("push", PushMode::avbd);
  CHECK(contains(usage_error("solver", avbd), "push avbd does not read --solver"));
  CHECK(contains(usage_error("friction-model", avbd), "does not read --friction-model"));
  CHECK(contains(usage_error("warm-start=0,0.8", avbd), "does not read --warm-start"));
  CHECK(contains(usage_error("row-precision", avbd), "does not read --row-precision"));
  scenes::Overrides xpbd;
  xpbd.set("push", PushMode::xpbd);
  CHECK(contains(usage_error("warm-start=0,0.8", xpbd), "push xpbd does not read --warm-start"));
  CHECK_NOTHROW(parse_comparison("solver", xpbd));  // xpbd's Jacobi averages its corrections
  CHECK_NOTHROW(parse_comparison("solver", push));  // split solves A lambda = b
  CHECK_NOTHROW(parse_comparison("row-precision", push));
  scenes::Overrides soft;
  soft.set("push", PushMode::soft);
  CHECK(contains(usage_error("row-precision", soft), "push soft does not read --row-precision"));
}

TEST_CASE("compared variants are laid out so that panels stay large", "[compare]") {
  const auto is = [](Grid g, int rows, int columns) { return g.rows == rows && g.columns == columns; };
  CHECK(is(grid_layout(1, 16.0 / 9.0), 1, 1));
  CHECK(is(grid_layout(2, 16.0 / 9.0), 1, 2));  // wide frame: side by side
  CHECK(is(grid_layout(2, 9.0 / 16.0), 2, 1));  // tall frame: one above the other
  CHECK(is(grid_layout(3, 16.0 / 9.0), 1, 3));
  CHECK(is(grid_layout(4, 1.0), 2, 2));
  CHECK(is(grid_layout(5, 16.0 / 9.0), 2, 3));
  CHECK(is(grid_layout(6, 16.0 / 9.0), 2, 3));
  CHECK(is(grid_layout(7, 16.0 / 9.0), 2, 4));
  CHECK(is(grid_layout(8, 16.0 / 9.0), 2, 4));
  CHECK_THROWS_AS(grid_layout(9, 1.0), std::invalid_argument);
  CHECK_THROWS_AS(grid_layout(0, 1.0), std::invalid_argument);
}

TEST_CASE("each comparison gets its own safe output name and run.json records it", "[compare]") {
  const Comparison push = parse_comparison("push", {});
  CHECK(comparison_suffix(push, false) == "-compare-push");  // as --compare push always wrote
  CHECK(comparison_suffix(push, true) == "-compare-push-overlay");
  const Comparison a = parse_comparison("beta=0.05,0.2,0.5", {});
  const Comparison b = parse_comparison("beta=0.05,0.2", {});
  const Comparison c = parse_comparison("beta=0.2,0.05", {});
  CHECK(comparison_suffix(a, false) == "-compare-beta-0.05_0.2_0.5");
  CHECK(comparison_suffix(b, false) != comparison_suffix(a, false));
  CHECK(comparison_suffix(c, false) != comparison_suffix(b, false));
  CHECK(comparison_suffix(parse_comparison("", {}), false).empty());
  // A fraction is written as its decimal value: no '/' in a file name.
  const std::string dt = comparison_suffix(parse_comparison("dt=1/60,1/30", {}), false);
  CHECK(dt.find('/') == std::string::npos);
  for (char ch : dt) {
    INFO(dt);
    CHECK((std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '-' || ch == '_' ||
           ch == '+'));
  }
  const nlohmann::json j = comparison_json(a, true);
  CHECK(j["parameter"] == "beta");
  CHECK(j["values"] == nlohmann::json({0.05, 0.2, 0.5}));
  CHECK(j["layout"] == "overlay");
  nlohmann::json every_push = nlohmann::json::array();
  for (const Choice& choice : parameter("push").choices) every_push.push_back(std::string(choice.name));
  CHECK(comparison_json(push, false)["values"] == every_push);
  CHECK(comparison_json(parse_comparison("", {}), false).is_null());
}

TEST_CASE("the overlay's colours are distinct hues", "[compare]") {
  // Hue (degrees) of an sRGB colour.
  const auto hue = [](const std::array<float, 3>& c) {
    const float mx = std::max({c[0], c[1], c[2]});
    const float mn = std::min({c[0], c[1], c[2]});
    const float d = mx - mn;
    float h = 0.0f;
    if (mx == c[0]) {
      h = 60.0f * std::fmod((c[1] - c[2]) / d, 6.0f);
    } else if (mx == c[1]) {
      h = 60.0f * ((c[2] - c[0]) / d + 2.0f);
    } else {
      h = 60.0f * ((c[0] - c[1]) / d + 4.0f);
    }
    return h < 0.0f ? h + 360.0f : h;
  };
  for (std::size_t i = 0; i < kMaxVariants; ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      float d = std::abs(hue(overlay_colour(i)) - hue(overlay_colour(j)));
      d = std::min(d, 360.0f - d);
      INFO(i << " " << j);
      CHECK(d > 25.0f);  // far enough apart to tell at a glance and in the pixel tests
    }
  }
  CHECK_THROWS_AS(overlay_colour(kMaxVariants), std::out_of_range);
}
