// The scene schema and the code that enforces it, compared so that neither drifts from the other.
//
//   test_scene_schema_code patterns SCHEMA_DIR
//     Every "pattern" keyword in schemas/*.schema.json is one the loader implements in code
//     (embra::io::schema_pattern_matches: the loader never hands a pattern to std::regex), and the
//     code accepts and refuses sample strings exactly as the pattern, read as the ECMAScript regular
//     expression JSON Schema means, does (std::regex here, on short strings only).
//   test_scene_schema_code limits SCHEMA_DIR
//     Every bound the schemas state for a value range or a size equals its constant in
//     core/include/embra/core/limits.hpp and its EMBRA_MAX_* / EMBRA_MIN_* macro in embra.h; and
//     every non-integer "minimum" or "maximum" anywhere in the schemas is one of those constants,
//     so a bound typed as a copy cannot drift.
#include "embra/core/kinds.hpp"
#include "embra/core/limits.hpp"
#include "embra/embra.h"
#include "embra/io/scene.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <functional>
#include <random>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using nlohmann::json;
namespace limits = embra::limits;

namespace {

int g_passed = 0, g_failed = 0;

void check(bool ok, const std::string& what) {
  if (ok) {
    ++g_passed;
  } else {
    ++g_failed;
    std::fprintf(stderr, "FAILED: %s\n", what.c_str());
  }
}

json read_schema(const std::string& dir, const char* name) {
  std::ifstream in(dir + "/" + name);
  if (!in) throw std::runtime_error("cannot read " + dir + "/" + name);
  std::stringstream s;
  s << in.rdbuf();
  return json::parse(s.str());
}

/// Calls `f(keyword, value, pointer)` for every keyword of every (sub)schema in `schema`. The keys of
/// "properties" and "definitions" are names; the values of const, enum, default and examples are
/// data, not schemas.
void each_keyword(const json& schema, const std::string& at,
                  const std::function<void(const std::string&, const json&, const std::string&)>& f) {
  if (schema.is_array()) {
    for (size_t i = 0; i < schema.size(); ++i) each_keyword(schema[i], at + "/" + std::to_string(i), f);
    return;
  }
  if (!schema.is_object()) return;
  for (const auto& [key, value] : schema.items()) {
    if (key == "const" || key == "enum" || key == "default" || key == "examples" || key == "required") continue;
    f(key, value, at);
    if (key == "properties" || key == "definitions") {
      for (const auto& [name, sub] : value.items()) each_keyword(sub, at + "/" + key + "/" + name, f);
    } else {
      each_keyword(value, at + "/" + key, f);
    }
  }
}

std::string shown(const std::string& s) {
  return json(s).dump(-1, ' ', true, json::error_handler_t::replace);
}

int patterns(const std::string& dir) {
  std::vector<std::string> found;
  for (const char* name : {"scene.schema.json", "tolerances.schema.json", "metrics.schema.json"}) {
    each_keyword(read_schema(dir, name), std::string(name) + "#",
                 [&](const std::string& key, const json& v, const std::string& at) {
                   check(key != "patternProperties" && !(key == "format" && v.is_string()),
                         at + ": \"" + key + "\" would be checked with std::regex");
                   if (key == "pattern" && v.is_string()) found.push_back(v.get<std::string>());
                 });
  }
  check(!found.empty(), "the scene schema names things with a pattern");
  // Samples: the empty string, every byte alone, every pair from characters near the class's edges,
  // the longest name, and random strings.
  std::vector<std::string> samples = {"", std::string(128, 'a'), "a\n", "\na", "a b", "_.:-", "A-Z", "[a]", "a$"};
  for (int c = 0; c < 256; ++c) samples.emplace_back(1, static_cast<char>(c));
  const std::string edges = "@AZ[`az{/09:;-._^ \t\\\x7f\x80\xc3\xa9";
  for (char a : edges)
    for (char b : edges) samples.push_back(std::string{a, b});
  std::mt19937 random(12345);
  std::uniform_int_distribution<int> length(1, 16), byte(0, 255), pick(0, static_cast<int>(edges.size()) - 1);
  for (int i = 0; i < 5000; ++i) {
    std::string s;
    const int n = length(random);
    for (int k = 0; k < n; ++k) s += i % 2 ? edges[pick(random)] : static_cast<char>(byte(random));
    samples.push_back(s);
  }
  for (const std::string& p : found) {
    bool implemented = true;
    try {
      embra::io::schema_pattern_matches(p, "a");
    } catch (const std::invalid_argument&) {
      implemented = false;
    }
    check(implemented, "the loader implements the schema's pattern " + shown(p));
    if (!implemented) continue;
    const std::regex re(p, std::regex::ECMAScript);
    int accepted = 0;
    for (const std::string& s : samples) {
      const bool want = std::regex_search(s, re);
      accepted += want;
      check(embra::io::schema_pattern_matches(p, s) == want,
            "pattern " + shown(p) + " on " + shown(s) + ": the regex says " + (want ? "match" : "no match"));
    }
    check(accepted > 0 && accepted < static_cast<int>(samples.size()), "the samples both match and fail " + shown(p));
    std::printf("pattern %s: %zu samples, %d match, code and regex agree\n", shown(p).c_str(), samples.size(),
                accepted);
  }
  // A pattern that is not the schema's is refused, not silently passed.
  bool refused = false;
  try {
    embra::io::schema_pattern_matches("^[a-z]+$", "a");
  } catch (const std::invalid_argument&) {
    refused = true;
  }
  check(refused, "schema_pattern_matches refuses a pattern it does not implement");
  return 0;
}

double number_at(const json& doc, const std::string& pointer) {
  return doc.at(json::json_pointer(pointer)).get<double>();
}

int64_t integer_at(const json& doc, const std::string& pointer) {
  return doc.at(json::json_pointer(pointer)).get<int64_t>();
}

std::string text_at(const json& doc, const std::string& pointer) {
  return doc.at(json::json_pointer(pointer)).get<std::string>();
}

void same(double schema, double constant, double macro, const std::string& what) {
  check(schema == constant,
        what + ": the schema says " + json(schema).dump() + ", limits.hpp " + json(constant).dump());
  check(macro == constant, what + ": embra.h says " + json(macro).dump() + ", limits.hpp " + json(constant).dump());
}

int limit_checks(const std::string& dir) {
  const json scene = read_schema(dir, "scene.schema.json");
  const json tol = read_schema(dir, "tolerances.schema.json");
  const std::string d = "/definitions/";
  // Value ranges.
  same(number_at(scene, d + "finite/maximum"), limits::kMaxAbsValue, EMBRA_MAX_ABS_VALUE, "finite maximum");
  same(-number_at(scene, d + "finite/minimum"), limits::kMaxAbsValue, EMBRA_MAX_ABS_VALUE, "finite minimum");
  same(number_at(scene, d + "non_negative/maximum"), limits::kMaxAbsValue, EMBRA_MAX_ABS_VALUE, "non_negative maximum");
  check(number_at(scene, d + "non_negative/minimum") == 0.0, "non_negative minimum is 0");
  same(number_at(scene, d + "positive/minimum"), limits::kMinPositive, EMBRA_MIN_POSITIVE, "positive minimum");
  same(number_at(scene, d + "positive/maximum"), limits::kMaxAbsValue, EMBRA_MAX_ABS_VALUE, "positive maximum");
  check(number_at(scene, d + "zero_or_positive/anyOf/0/minimum") == 0.0 &&
            number_at(scene, d + "zero_or_positive/anyOf/0/maximum") == 0.0,
        "zero_or_positive: 0");
  check(text_at(scene, d + "zero_or_positive/anyOf/1/$ref") == "#/definitions/positive", "zero_or_positive: positive");
  same(number_at(scene, d + "solver/properties/dt/minimum"), limits::kMinPositive, EMBRA_MIN_POSITIVE, "dt minimum");
  same(number_at(scene, d + "solver/properties/dt/maximum"), limits::kMaxDt, EMBRA_MAX_DT, "dt maximum");
  same(number_at(tol, "/properties/unit_scale/minimum"), limits::kMinPositive, EMBRA_MIN_POSITIVE,
       "unit_scale minimum");
  same(number_at(tol, "/properties/unit_scale/maximum"), limits::kMaxUnitScale, EMBRA_MAX_UNIT_SCALE,
       "unit_scale maximum");
  for (const char* k : {"target", "max"})
    same(number_at(tol, std::string("/definitions/tolerance/properties/") + k + "/maximum"), limits::kMaxAbsValue,
         EMBRA_MAX_ABS_VALUE, std::string("tolerance ") + k + " maximum");
  // Sizes.
  const double particles = static_cast<double>(integer_at(scene, d + "inline_mesh/properties/vertices/maxItems"));
  same(particles, static_cast<double>(limits::kMaxParticles), EMBRA_MAX_PARTICLES, "inline mesh vertices");
  for (const char* k : {"positions", "velocities"})
    same(static_cast<double>(integer_at(scene, d + "state/properties/" + k + "/maxItems")),
         static_cast<double>(limits::kMaxParticles), EMBRA_MAX_PARTICLES, std::string("state ") + k);
  for (const char* at : {"panel_mesh/then/properties/quads/maxItems", "panel_mesh/else/properties/quads/maxItems"})
    same(static_cast<double>(integer_at(scene, d + at)), static_cast<double>(limits::kMaxParticles / 8),
         EMBRA_MAX_PARTICLES / 8, std::string(at) + " (8 particles per panel)");
  // A constraint's operands: as many as the kinds take, the fewest to the most.
  int fewest = 1 << 30, most = 0;
  for (const embra::KindInfo& k : embra::kKinds) fewest = std::min(fewest, k.arity), most = std::max(most, k.arity);
  check(integer_at(scene, d + "constraint_batch/properties/particles/items/minItems") == fewest,
        "constraint operands minItems = the smallest arity " + std::to_string(fewest));
  check(integer_at(scene, d + "constraint_batch/properties/particles/items/maxItems") == most,
        "constraint operands maxItems = the largest arity " + std::to_string(most));
  // What a schema cannot express is stated in its descriptions, with the same numbers.
  const auto says = [&](const std::string& pointer, int64_t value, const char* macro) {
    const std::string text = text_at(scene, pointer);
    check(text.find(std::to_string(value)) != std::string::npos && text.find(macro) != std::string::npos,
          pointer + " states " + std::to_string(value) + " (" + macro + "): " + text);
  };
  says(d + "solver/properties/substeps/description", limits::kMaxPassesPerStep, "EMBRA_MAX_PASSES_PER_STEP");
  check(EMBRA_MAX_PASSES_PER_STEP == limits::kMaxPassesPerStep, "EMBRA_MAX_PASSES_PER_STEP");
  says(d + "obj_mesh/properties/obj/description", limits::kMaxObjBytes, "EMBRA_MAX_OBJ_BYTES");
  says(d + "panel_mesh/then/properties/obj/description", limits::kMaxObjBytes, "EMBRA_MAX_OBJ_BYTES");
  check(EMBRA_MAX_OBJ_BYTES == limits::kMaxObjBytes, "EMBRA_MAX_OBJ_BYTES");
  check(EMBRA_MAX_CONSTRAINTS == limits::kMaxConstraints, "EMBRA_MAX_CONSTRAINTS");
  // No other copy: every bound that is not a whole number is one of the constants (or the unit
  // quaternion's components, at most 1 + 1e-6 in magnitude).
  const std::vector<double> known = {limits::kMaxAbsValue,
                                     -limits::kMaxAbsValue,
                                     limits::kMinPositive,
                                     limits::kMaxDt,
                                     limits::kMaxUnitScale,
                                     1.000001,
                                     -1.000001};
  int bounds = 0;
  for (const json* doc : {&scene, &tol})
    each_keyword(*doc, "#", [&](const std::string& key, const json& v, const std::string& at) {
      if (key != "minimum" && key != "maximum" && key != "exclusiveMinimum" && key != "exclusiveMaximum") return;
      ++bounds;
      check(key == "minimum" || key == "maximum", at + ": \"" + key + "\" (the loader checks minimum and maximum)");
      if (!v.is_number_float()) return;
      const double x = v.get<double>();
      check(std::find(known.begin(), known.end(), x) != known.end(),
            at + "/" + key + " = " + v.dump() + " is none of limits.hpp's constants");
    });
  std::printf("%d bounds in the schemas checked\n", bounds);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: test_scene_schema_code patterns|limits SCHEMA_DIR\n");
    return 2;
  }
  const std::string mode = argv[1];
  try {
    if (mode == "patterns")
      patterns(argv[2]);
    else if (mode == "limits")
      limit_checks(argv[2]);
    else
      return 2;
  } catch (const std::exception& e) {
    check(false, std::string("exception: ") + e.what());
  }
  std::printf("%d passed, %d failed\n", g_passed, g_failed);
  return g_failed == 0 ? 0 : 1;
}
