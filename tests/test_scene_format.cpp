// Scene validation (the runner's input contract): every bad input is one clear
// SceneError naming the key; a good scene resolves with its defaults.
#include <gtest/gtest.h>

#include "nhi/runner/output.hpp"
#include "nhi/runner/scene.hpp"

namespace nhi {
namespace {

json good() {
  return json::parse(R"({"system": "particle", "q0": [1, 0.5, 0], "v0": [0.5, 1, 0.25],
                         "method": "dla", "h": 0.2, "steps": 10})");
}

TEST(Scene, ResolvesDefaults) {
  const json r = validate_scene(good());
  EXPECT_EQ(r["discretization"], "alpha");
  EXPECT_EQ(r["alpha"], 0.5);
  EXPECT_EQ(r["tolerance"], 1e-12);
  EXPECT_EQ(r["output_every"], 1);
  EXPECT_EQ(r["params"]["kx"], 1.0);
  EXPECT_EQ(r["params"]["ky"], 1.0);
  EXPECT_EQ(r["composition"], "none");
}

// The methods after the paper and the DLA resolve with every composition.
TEST(Scene, NewMethodsAndCompositionsResolve) {
  for (const char* method : {"mp06", "discrete_gradient", "dla"})
    for (const char* c : {"none", "triple_jump", "suzuki5", "order6"}) {
      json s = good();
      s["method"] = method;
      s["composition"] = c;
      const json r = validate_scene(s);
      EXPECT_EQ(r["method"], method);
      EXPECT_EQ(r["composition"], c);
    }
}

struct Bad {
  const char* what;
  const char* key;  // the key the message must name
  std::function<void(json&)> edit;
};

// The memory refusal depends on the stride, not on the steps alone.
TEST(Scene, RefusesOnlyRunsWhosePointsCannotFit) {
  json s = good();
  s["method"] = "rk4";
  s["steps"] = 100000000;
  try {
    validate_scene(s);
    ADD_FAILURE() << "10^8 recorded points accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("'output_every'"), std::string::npos) << e.what();
  }
  s["output_every"] = 100000;
  EXPECT_NO_THROW(validate_scene(s));
}

TEST(Scene, RejectsBadInputNamingTheKey) {
  const std::vector<Bad> cases = {
      {"unknown system", "system", [](json& s) { s["system"] = "pendulum"; }},
      {"unknown method", "method", [](json& s) { s["method"] = "euler"; }},
      {"unknown discretization", "discretization", [](json& s) { s["discretization"] = "trapezoid"; }},
      {"q0 too short", "q0",
       [](json& s) {
         s["q0"] = {1, 2};
       }},
      {"v0 too long", "v0",
       [](json& s) {
         s["v0"] = {0, 0, 0, 0};
       }},
      {"q0 not an array", "q0", [](json& s) { s["q0"] = 3; }},
      {"q0 entry a string", "q0[1]",
       [](json& s) {
         s["q0"] = {1, "a", 0};
       }},
      {"alpha above 1", "alpha", [](json& s) { s["alpha"] = 1.0000001; }},
      {"alpha below 0", "alpha", [](json& s) { s["alpha"] = -1e-9; }},
      {"h zero", "h", [](json& s) { s["h"] = 0; }},
      {"h negative", "h", [](json& s) { s["h"] = -0.1; }},
      {"h infinite", "h", [](json& s) { s["h"] = std::numeric_limits<double>::infinity(); }},
      {"steps zero", "steps", [](json& s) { s["steps"] = 0; }},
      {"steps zero (unsigned)", "steps", [](json& s) { s["steps"] = 0u; }},
      {"output_every zero (parsed)", "output_every", [](json& s) { s["output_every"] = json::parse("0"); }},
      {"steps negative", "steps", [](json& s) { s["steps"] = -5; }},
      {"steps fractional", "steps", [](json& s) { s["steps"] = 1.5; }},
      {"steps a string", "steps", [](json& s) { s["steps"] = "10"; }},
      {"v0 off the constraint", "v0",
       [](json& s) {
         s["v0"] = {0.5, 1, 0.3};
       }},
      {"unknown key", "stepz", [](json& s) { s["stepz"] = 3; }},
      {"missing method", "method", [](json& s) { s.erase("method"); }},
      {"missing h", "h", [](json& s) { s.erase("h"); }},
      {"unknown parameter", "params.mass",
       [](json& s) {
         s["params"] = {{"mass", 2}};
       }},
      {"params not an object", "params",
       [](json& s) {
         s["params"] = {1, 2};
       }},
      {"tolerance zero", "tolerance", [](json& s) { s["tolerance"] = 0; }},
      {"output_every zero", "output_every", [](json& s) { s["output_every"] = 0; }},
      {"NaN entry", "v0[0]", [](json& s) { s["v0"][0] = std::nan(""); }},
      {"composition of a non-symmetric DLA", "composition",
       [](json& s) {
         s["alpha"] = 0.25;
         s["composition"] = "triple_jump";
       }},
      {"composition of rk4", "composition",
       [](json& s) {
         s["method"] = "rk4";
         s["composition"] = "order6";
       }},
      {"unknown composition", "composition",
       [](json& s) {
         s["method"] = "mp06";
         s["composition"] = "order8";
       }},
      {"composition not a string", "composition",
       [](json& s) {
         s["method"] = "mp06";
         s["composition"] = 4;
       }},
      // make fuzz found this one: the message's dump() threw on invalid UTF-8.
      {"string with invalid UTF-8 (--set fallback)", "params.kx",
       [](json& s) { apply_override(&s, "params.kx=\x86\x86\x86"); }},
  };
  for (const auto& c : cases) {
    json s = good();
    c.edit(s);
    try {
      validate_scene(s);
      ADD_FAILURE() << c.what << ": accepted";
    } catch (const SceneError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(std::string("'") + c.key + "'"), std::string::npos)
          << c.what << ": message does not name '" << c.key << "': " << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << c.what << ": not one line";
    }
  }
}

TEST(Scene, OverridesThatCannotBeAValueNameTheKey) {
  // make fuzz found "--set h=31e308": nlohmann's out_of_range escaped apply_override.
  for (const char* a : {"h=31e308", "h=-1e999", "params.kx=1e400"}) {
    json s = good();
    try {
      apply_override(&s, a);
      validate_scene(s);
      ADD_FAILURE() << a << ": accepted";
    } catch (const SceneError& e) {
      const std::string key = std::string(a).substr(0, std::string(a).find('='));
      EXPECT_NE(std::string(e.what()).find("'" + key + "'"), std::string::npos) << e.what();
    }
  }
}

json good_robot() {
  return json::parse(R"({"system": "robot", "q0": [0, 0, 0, 0], "v0": [1, 0, 1, 1],
                         "method": "dla", "h": 0.2, "steps": 10})");
}

TEST(Scene, RobotResolvesDefaultsAndRejectsBadInput) {
  const json r = validate_scene(good_robot());
  EXPECT_EQ(r["params"], json::parse(R"({"m": 1.0, "I": 1.0, "Iw": 0.3333333333333333, "R": 1.0, "V0": 10.0})"));
  const std::vector<Bad> cases = {
      {"q0 of particle length", "q0",
       [](json& s) {
         s["q0"] = {0, 0, 0};
       }},
      {"v0 too long", "v0",
       [](json& s) {
         s["v0"] = {1, 0, 1, 1, 0};
       }},
      {"v0 off the first constraint", "v0",
       [](json& s) {
         s["v0"] = {0.5, 0, 1, 1};
       }},
      {"v0 off the second constraint (turned wheels)", "v0",
       [](json& s) {
         s["q0"] = {0, 0, 1.0, 0};
       }},
      {"negative mass", "params.m",
       [](json& s) {
         s["params"] = {{"m", -1}};
       }},
      {"zero wheel radius", "params.R",
       [](json& s) {
         s["params"] = {{"R", 0}};
       }},
      {"particle parameter", "params.kx",
       [](json& s) {
         s["params"] = {{"kx", 1}};
       }},
  };
  for (const auto& c : cases) {
    json s = good_robot();
    c.edit(s);
    try {
      validate_scene(s);
      ADD_FAILURE() << c.what << ": accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + c.key + "'"), std::string::npos)
          << c.what << ": " << e.what();
    }
  }
}

// At most kMaxSceneDepth arrays and objects around any value, in a scene file
// and in a --set value; one more is refused naming the limit.
TEST(Scene, NestingBeyondTheLimitIsRefused) {
  const auto nested = [](int depth) { return std::string(depth, '[') + "1" + std::string(depth, ']'); };
  EXPECT_NO_THROW(parse_scene_text(nested(kMaxSceneDepth), "test"));
  try {
    parse_scene_text(nested(kMaxSceneDepth + 1), "test");
    ADD_FAILURE() << "not refused";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("nested deeper than " + std::to_string(kMaxSceneDepth)), std::string::npos)
        << e.what();
  }
  json s = good();
  EXPECT_NO_THROW(apply_override(&s, "params.kx=" + nested(kMaxSceneDepth)));
  EXPECT_THROW(apply_override(&s, "params.kx=" + nested(kMaxSceneDepth + 1)), SceneError);
}

TEST(Scene, OverridesParseJsonOrFallBackToString) {
  json s = good();
  apply_override(&s, "alpha=0.25");
  apply_override(&s, "q0=[2,0,0]");
  apply_override(&s, "method=rk4");
  apply_override(&s, "params.ky=3");
  EXPECT_EQ(s["alpha"], 0.25);
  EXPECT_EQ(s["q0"], json::parse("[2,0,0]"));
  EXPECT_EQ(s["method"], "rk4");
  EXPECT_EQ(s["params"]["ky"], 3);
  EXPECT_THROW(apply_override(&s, "novalue"), SceneError);
}

TEST(Scene, RunRecordsEveryPointAndTheSummary) {
  json s = good();
  s["steps"] = 7;
  s["output_every"] = 3;
  const json r = run_scene(validate_scene(s));
  ASSERT_EQ(r["status"], "ok");
  // Points 0, 3, 6 and the last one, 7.
  ASSERT_EQ(r["t"].size(), 4u);
  EXPECT_DOUBLE_EQ(r["t"][3].get<double>(), 7 * 0.2);
  EXPECT_EQ(r["q"].size(), 4u);
  EXPECT_EQ(r["p"].size(), 4u);
  EXPECT_EQ(r["lambda"][0].size(), 1u);
  // The summary's maxima cover every point, the recorded ones included.
  double recorded = 0;
  for (const auto& e : r["energy"])
    recorded = std::max(recorded, std::abs(e.get<double>() - r["energy"][0].get<double>()));
  EXPECT_GE(r["summary"]["max_abs_energy_error"].get<double>(), recorded);
  // Same run at stride 1: the summary is identical.
  s["output_every"] = 1;
  const json full = run_scene(validate_scene(s));
  EXPECT_EQ(full["t"].size(), 8u);
  EXPECT_EQ(full["summary"]["max_abs_energy_error"], r["summary"]["max_abs_energy_error"]);
  EXPECT_EQ(full["summary"]["max_abs_constraint"], r["summary"]["max_abs_constraint"]);
}

// A result's text (json_lines): the same JSON, a line per member and per
// element of a long array, rows of numbers on one line, numbers as dump() writes them.
TEST(ResultText, IsTheSameJsonWithOneRowALine) {
  json r = {{"status", "ok"}, {"x", 0.1}, {"empty", json::array()}, {"none", json::object()}};
  for (int i = 0; i < 40; ++i) {
    r["t"].push_back(0.1 * i);
    r["q"].push_back({1.0 / (i + 1), -2.5e-300, i});
  }
  r["meta"] = {{"git_revision", "abc"}, {"nested", {{"k", {1, 2}}}}};
  const std::string text = json_lines(r);
  EXPECT_EQ(json::parse(text), r);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  size_t lines = 0;
  for (char c : text) lines += c == '\n';
  EXPECT_GT(lines, 80u);  // 40 times, 40 rows of q, and the members
  EXPECT_NE(text.find("\n  " + r["q"][3].dump() + ",\n"), std::string::npos) << text.substr(0, 400);
  EXPECT_NE(text.find("\n  " + r["t"][7].dump() + ",\n"), std::string::npos);
  EXPECT_NE(text.find("\"k\": [1,2]"), std::string::npos);
}

}  // namespace
}  // namespace nhi
