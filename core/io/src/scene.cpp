// Scene documents: parse (nlohmann-json), validate (valijson against the compiled-in schema), build
// through embra::World, and save back.
#include "embra/io/scene.hpp"

#include "embra/io/files.hpp"

#include "embra/core/kinds.hpp"
#include "embra/core/limits.hpp"

#include "closed_meshes.hpp"
#include "scene_schema.hpp"

#include <nlohmann/json.hpp>
#include <valijson/adapters/nlohmann_json_adapter.hpp>
#include <valijson/constraint_builder.hpp>
#include <valijson/constraints/concrete_constraints.hpp>
#include <valijson/schema.hpp>
#include <valijson/schema_parser.hpp>
#include <valijson/validator.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <limits>
#include <memory>
#include <new>
#include <numbers>
#include <set>
#include <span>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <type_traits>

namespace embra::io {

using nlohmann::json;

namespace {

constexpr int kMaxDepth = 64;  // scenes nest 8 deep; anything far deeper is refused before parsing

[[noreturn]] void fail(const std::string& pointer, const std::string& message) {
  throw SceneError((pointer.empty() ? std::string("/") : pointer) + ": " + message);
}

/// Parses JSON text, refusing nesting deeper than kMaxDepth while parsing (so a hostile document
/// costs neither stack nor memory) and anything that is not JSON (including invalid UTF-8).
json parse(std::string_view text) {
  try {
    return json::parse(text.begin(), text.end(), [](int depth, json::parse_event_t event, json&) {
      // `depth` counts the containers already open, so the 65th object or array starts at 64.
      const bool opens = event == json::parse_event_t::object_start || event == json::parse_event_t::array_start;
      if (opens && depth >= kMaxDepth)
        throw SceneError("/: the document nests deeper than " + std::to_string(kMaxDepth) + " levels");
      return true;
    });
  } catch (const json::exception& e) {
    std::string what = e.what();
    const auto pos = what.find("] ");
    // nlohmann quotes the bytes it last read, which may be the very invalid UTF-8 it refused: spell
    // non-ASCII bytes as \xNN so the message itself is always valid UTF-8 (hosts decode it).
    std::string ascii;
    for (const char ch : pos == std::string::npos ? what : what.substr(pos + 2)) {
      const auto byte = static_cast<unsigned char>(ch);
      if (byte < 0x80) {
        ascii += ch;
      } else {
        const char* hex = "0123456789abcdef";
        ascii += {'\\', 'x', hex[byte >> 4], hex[byte & 15]};
      }
    }
    throw SceneError("/: not valid JSON: " + ascii);
  }
}

/// valijson's context ("<root>", "[bodies]", "[0]", ...) as the tokens of a JSON pointer.
std::vector<std::string> tokens_of(const std::vector<std::string>& context) {
  std::vector<std::string> tokens;
  for (const std::string& c : context) {
    if (c == "<root>") continue;
    std::string token = c.size() >= 2 && c.front() == '[' && c.back() == ']' ? c.substr(1, c.size() - 2) : c;
    if (token.size() >= 2 && token.front() == '"' && token.back() == '"') token = token.substr(1, token.size() - 2);
    tokens.push_back(std::move(token));
  }
  return tokens;
}

/// valijson's context as a JSON pointer.
std::string pointer_of(const std::vector<std::string>& context) {
  std::string p;
  for (const std::string& token : tokens_of(context)) p += "/" + token;
  return p.empty() ? "/" : p;
}

// --- keywords the loader checks itself -------------------------------------------------------------
// valijson checks "pattern" with std::regex, whose recursive matcher overflows the stack on a long
// string (a 30,000-character name crashed the process) and whose construction races in
// libstdc++'s locale caches when scenes load on several threads; and it prints the bounds of
// "minimum" and "maximum" with std::to_string, which shows 1e-300 as "0.000000". The schema keeps
// its standard keywords (for every other validator); the loader hands them to valijson under
// keywords of its own, checked by the constraints below, and refuses to compile a schema holding
// a pattern they do not implement, or a keyword that would bring std::regex back
// ("patternProperties", "format").

/// The one pattern the scene schema uses: names of groups, bodies, pins, colliders, fields, sets.
constexpr std::string_view kNamePattern = "^[A-Za-z0-9_.:-]+$";
constexpr const char* kPatternKeyword = "x-embra-pattern";
constexpr const char* kRangeKeyword = "x-embra-range";  // {"minimum": a, "maximum": b} as the schema gives them

bool name_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '.' ||
         c == ':' || c == '-';
}

bool matches_name_pattern(std::string_view text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), name_char);
}

/// A number as people write it: integers whole, others in the shortest form that reads back
/// exactly (1e-300, not 0.000000).
std::string number_text(double v) {
  if (v == std::floor(v) && std::abs(v) < 1e15) return std::to_string(static_cast<int64_t>(v));
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;
  return std::string(buffer, end);
}

/// A schema "pattern" the loader implements, checked in linear time without recursion.
class PatternConstraint : public valijson::constraints::PolyConstraint {
 public:
  bool validate(const valijson::adapters::Adapter& target, const std::vector<std::string>& context,
                valijson::ValidationResults* results) const override {
    if (!target.isString()) return true;  // "pattern" constrains strings only
    if (matches_name_pattern(target.asString())) return true;
    if (results != nullptr)
      results->pushError(context,
                         "a name holds only letters A-Z and a-z, digits and the characters _ . : - "
                         "(the schema's pattern ^[A-Za-z0-9_.:-]+$)");
    return false;
  }

 private:
  valijson::constraints::Constraint* cloneInto(void* memory) const override {
    return new (memory) PatternConstraint(*this);
  }
  size_t sizeOf() const override { return sizeof(PatternConstraint); }
};

/// "minimum" and "maximum" (inclusive, as draft 7 defines them) of a number.
class RangeConstraint : public valijson::constraints::PolyConstraint {
 public:
  RangeConstraint(double minimum, double maximum) : minimum_(minimum), maximum_(maximum) {}

  bool validate(const valijson::adapters::Adapter& target, const std::vector<std::string>& context,
                valijson::ValidationResults* results) const override {
    if (!target.isNumber()) return true;  // as valijson: the bounds constrain numbers only
    const double v = target.asDouble();
    bool ok = true;
    if (v < minimum_) {
      ok = false;
      if (results != nullptr)
        results->pushError(context, "Expected number greater than or equal to " + number_text(minimum_));
    }
    if (v > maximum_) {
      ok = false;
      if (results != nullptr)
        results->pushError(context, "Expected number less than or equal to " + number_text(maximum_));
    }
    return ok;
  }

 private:
  valijson::constraints::Constraint* cloneInto(void* memory) const override {
    return new (memory) RangeConstraint(*this);
  }
  size_t sizeOf() const override { return sizeof(RangeConstraint); }

  double minimum_, maximum_;
};

class PatternConstraintBuilder : public valijson::ConstraintBuilder {
 public:
  valijson::constraints::Constraint* make(const valijson::adapters::Adapter& value) const override {
    if (!value.isString() || value.asString() != kNamePattern)
      throw std::logic_error("the scene schema has a \"pattern\" the loader does not implement");
    return new PatternConstraint();
  }
};

class RangeConstraintBuilder : public valijson::ConstraintBuilder {
 public:
  valijson::constraints::Constraint* make(const valijson::adapters::Adapter& value) const override {
    double minimum = -std::numeric_limits<double>::infinity(), maximum = std::numeric_limits<double>::infinity();
    value.applyToObject([&](const std::string& key, const valijson::adapters::Adapter& bound) {
      if (!bound.isNumber()) throw std::logic_error("a bound of the scene schema is not a number");
      (key == "minimum" ? minimum : maximum) = bound.asDouble();
      return true;
    });
    return new RangeConstraint(minimum, maximum);
  }
};

/// Moves the keywords of a schema that the loader checks itself (see above) to its own keywords.
/// Keywords whose values are data (const, enum, default, examples, required) are left alone; the
/// keys of "properties" and "definitions" are names, their values schemas.
void move_keywords(json& schema) {
  if (schema.is_array()) {
    for (json& item : schema) move_keywords(item);
    return;
  }
  if (!schema.is_object()) return;
  for (auto it = schema.begin(); it != schema.end(); ++it) {
    const std::string& key = it.key();
    if (key == "const" || key == "enum" || key == "default" || key == "examples" || key == "required") continue;
    if (key == "patternProperties" || key == "exclusiveMinimum" || key == "exclusiveMaximum" ||
        (key == "format" && it->is_string()))
      throw std::logic_error("the scene schema uses \"" + key + "\", which the loader does not check itself");
    if (key == "properties" || key == "definitions") {
      for (json& sub : *it) move_keywords(sub);
    } else {
      move_keywords(*it);
    }
  }
  const auto pattern = schema.find("pattern");
  if (pattern != schema.end() && pattern->is_string()) {
    schema[kPatternKeyword] = *pattern;
    schema.erase("pattern");
  }
  for (const char* bound : {"minimum", "maximum"}) {
    const auto it = schema.find(bound);
    if (it != schema.end() && it->is_number()) {
      schema[kRangeKeyword][bound] = *it;
      schema.erase(bound);
    }
  }
}

std::unique_ptr<valijson::Schema> parse_schema(std::string_view text) {
  auto s = std::make_unique<valijson::Schema>();
  json doc = json::parse(text);
  move_keywords(doc);
  valijson::SchemaParser parser;
  parser.addConstraintBuilder(kPatternKeyword, new PatternConstraintBuilder());  // the parser owns them
  parser.addConstraintBuilder(kRangeKeyword, new RangeConstraintBuilder());
  valijson::adapters::NlohmannJsonAdapter adapter(doc);
  parser.populateSchema(adapter, *s);
  return s;
}

bool all_digits(const std::string& token) {
  return !token.empty() && token.size() < 10 &&
         std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; });
}

/// A schema, compiled for valijson, and as written (for the words of its error messages).
struct CompiledSchema {
  std::unique_ptr<valijson::Schema> schema;
  json source;
};

/// The schemas, parsed once (thread-safe static initialisation).
const CompiledSchema& scene_schema_compiled() {
  static const CompiledSchema schema{parse_schema(scene_schema()), json::parse(scene_schema())};
  return schema;
}

const CompiledSchema& tolerances_schema_compiled() {
  static const CompiledSchema schema{parse_schema(kTolerancesSchema), json::parse(kTolerancesSchema)};
  return schema;
}

// --- errors in words ---------------------------------------------------------------------------------
// valijson says "Object contains a property that could not be validated using 'properties' or
// 'additionalProperties' constraints: 'gravty'." and "Value type not permitted by 'type'
// constraint."; the schema as written says what the place accepts, so the message can say it too.

/// Every subschema of `schema` that applies at `path` below it ($ref, allOf, anyOf, oneOf, then and
/// else followed; properties, additionalProperties and items descended). At most kSchemaVisits
/// subschemas are visited, whatever the document's path (the schemas are fixed, the path is not).
constexpr int kSchemaVisits = 4096;
void schemas_at(const json& root, const json& schema, std::span<const std::string> path, std::vector<const json*>& out,
                int& visits) {
  if (!schema.is_object() || ++visits > kSchemaVisits) return;
  if (const auto ref = schema.find("$ref"); ref != schema.end() && ref->is_string()) {
    const std::string& r = ref->get_ref<const std::string&>();
    if (r.starts_with("#")) {
      const json::json_pointer at(r.substr(1));
      if (root.contains(at)) schemas_at(root, root.at(at), path, out, visits);
    }
  }
  for (const char* combinator : {"allOf", "anyOf", "oneOf"})
    if (const auto list = schema.find(combinator); list != schema.end() && list->is_array())
      for (const json& sub : *list) schemas_at(root, sub, path, out, visits);
  for (const char* branch : {"then", "else"})
    if (const auto sub = schema.find(branch); sub != schema.end()) schemas_at(root, *sub, path, out, visits);
  if (path.empty()) {
    out.push_back(&schema);
    return;
  }
  const std::string& token = path.front();
  const auto properties = schema.find("properties");
  if (properties != schema.end() && properties->is_object() && properties->contains(token)) {
    schemas_at(root, properties->at(token), path.subspan(1), out, visits);
  } else if (const auto extra = schema.find("additionalProperties"); extra != schema.end() && extra->is_object()) {
    schemas_at(root, *extra, path.subspan(1), out, visits);
  }
  if (const auto items = schema.find("items"); items != schema.end() && all_digits(token)) {
    if (items->is_object()) schemas_at(root, *items, path.subspan(1), out, visits);
    const size_t i = std::stoul(token);
    if (items->is_array() && i < items->size()) schemas_at(root, items->at(i), path.subspan(1), out, visits);
  }
}

/// The number of single-character edits from a to b (both short: keys of a schema).
size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

/// "a number", "a whole number", ... : a JSON Schema type as people say it.
std::string type_words(const std::string& type) {
  if (type == "integer") return "a whole number";
  if (type == "array" || type == "object") return "an " + type;
  if (type == "boolean") return "true or false";
  if (type == "null") return "null";
  return "a " + type;
}

/// What a JSON value is, as people say it.
std::string value_words(const json& v) {
  switch (v.type()) {
    case json::value_t::string:
      return "a string";
    case json::value_t::boolean:
      return v.get<bool>() ? "true" : "false";
    case json::value_t::null:
      return "null";
    case json::value_t::array:
      return "an array";
    case json::value_t::object:
      return "an object";
    case json::value_t::number_float:
      return "the number " + number_text(v.get<double>());
    default:
      return "a whole number";
  }
}

/// The value of `doc` at `path` (null when there is none).
const json* value_at(const json& doc, std::span<const std::string> path) {
  const json* v = &doc;
  for (const std::string& token : path) {
    if (v->is_object() && v->contains(token)) {
      v = &v->at(token);
    } else if (v->is_array() && all_digits(token) && std::stoul(token) < v->size()) {
      v = &v->at(std::stoul(token));
    } else {
      return nullptr;
    }
  }
  return v;
}

/// One validation error in words: an unknown key with the nearest known one, a missing key, a wrong
/// type with the types accepted and the value found; any other error as valijson says it.
std::string error_words(const std::string& description, const json& doc, const json& schema,
                        const std::vector<std::string>& path) {
  std::vector<const json*> here;
  int visits = 0;
  schemas_at(schema, schema, path, here, visits);
  constexpr std::string_view kUnknown =
      "could not be validated using 'properties' or 'additionalProperties' constraints: '";
  if (const auto at = description.find(kUnknown); at != std::string::npos) {
    std::string key = description.substr(at + kUnknown.size());
    while (!key.empty() && (key.back() == '.' || key.back() == '\'')) key.pop_back();
    std::vector<std::string> known;
    for (const json* s : here)
      if (const auto p = s->find("properties"); p != s->end() && p->is_object())
        for (auto it = p->begin(); it != p->end(); ++it) known.push_back(it.key());
    if (std::find(known.begin(), known.end(), key) != known.end())
      return "key '" + key + "' cannot be used together with the other keys here";
    std::string nearest;
    size_t best = std::max<size_t>(1, key.size() / 3) + 1;
    for (const std::string& k : known)
      if (const size_t d = edit_distance(key, k); d < best) best = d, nearest = k;
    return "unknown key '" + key + "'" + (nearest.empty() ? "" : " (did you mean '" + nearest + "'?)");
  }
  constexpr std::string_view kMissing = "Missing required property '";
  if (description.starts_with(kMissing)) {
    std::string key = description.substr(kMissing.size());
    while (!key.empty() && (key.back() == '.' || key.back() == '\'')) key.pop_back();
    return "missing key '" + key + "'";
  }
  if (description.starts_with("Value type not permitted by 'type' constraint")) {
    std::vector<std::string> types;
    for (const json* s : here)
      if (const auto t = s->find("type"); t != s->end())
        for (const json& name : t->is_array() ? *t : json::array({*t}))
          if (name.is_string() && std::find(types.begin(), types.end(), name.get<std::string>()) == types.end())
            types.push_back(name.get<std::string>());
    if (types.empty()) return description;
    std::string expected;
    for (size_t i = 0; i < types.size(); ++i)
      expected += (i == 0 ? "" : i + 1 == types.size() ? " or " : ", ") + type_words(types[i]);
    const json* value = value_at(doc, path);
    return "expected " + expected + (value ? ", got " + value_words(*value) : "");
  }
  return description;
}

/// Validates `doc` against `schema`; errors name their pointer below `prefix`.
void validate(const json& doc, const CompiledSchema& schema, const std::string& prefix, const char* what) {
  valijson::Validator validator;
  valijson::ValidationResults results;
  valijson::adapters::NlohmannJsonAdapter adapter(doc);
  if (validator.validate(*schema.schema, adapter, &results)) return;
  // oneOf and anyOf failures report every alternative; the deepest error is the most telling, and
  // every distinct error at its place says what would have been accepted (0, or at least 1e-300).
  std::vector<valijson::ValidationResults::Error> errors;
  valijson::ValidationResults::Error e;
  while (results.popError(e)) errors.push_back(e);
  if (errors.empty()) fail(prefix, std::string("does not match the ") + what + " schema");
  const valijson::ValidationResults::Error* deepest = &errors.front();
  for (const auto& err : errors)
    if (err.context.size() > deepest->context.size()) deepest = &err;
  // allOf and if-then-else only repeat that something below them failed.
  auto wrapper = [](const std::string& d) {
    return d.starts_with("Failed to validate against child schema #") ||
           d.starts_with("Failed to validate against a conditional schema");
  };
  const std::vector<std::string> path = tokens_of(deepest->context);
  std::vector<std::string> said;
  bool in_words = false;  // some error said in the schema's words: no need to name the schema
  for (const auto& err : errors) {
    if (err.context != deepest->context || (wrapper(err.description) && err.description != deepest->description))
      continue;
    const std::string words = error_words(err.description, doc, schema.source, path);
    in_words = in_words || words != err.description;
    if (std::find(said.begin(), said.end(), words) == said.end()) said.push_back(words);
  }
  // Said in words, the place needs no "Failed to validate against any schemas allowed by anyOf".
  if (in_words) std::erase_if(said, [](const std::string& d) { return d.starts_with("Failed to validate against"); });
  std::string message;
  for (std::string d : said) {
    if (said.size() > 1 && d.ends_with('.')) d.pop_back();
    message += (message.empty() ? "" : "; ") + d;
  }
  const std::string pointer = pointer_of(deepest->context);
  fail(prefix.empty() ? pointer : prefix + (pointer == "/" ? "" : pointer),
       !in_words                           ? std::string("does not match the ") + what + " schema: " + message
       : std::string_view(what) != "scene" ? message + " (the " + what + " schema)"
                                           : message);
}

constexpr const char* kColliderShapeNames[kColliderShapeCount] = {"plane",   "sphere", "box",
                                                                  "capsule", "convex", "mesh"};

/// The shape a scene names (the schema has checked it is one of kColliderShapeNames).
ColliderShape collider_shape(const std::string& name) {
  for (int k = 0; k < kColliderShapeCount; ++k)
    if (name == kColliderShapeNames[k]) return static_cast<ColliderShape>(k);
  return ColliderShape::plane;
}

Vec3 vec3(const json& j) {
  return Vec3(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
}

Eigen::Quaterniond quat(const json& j, const std::string& where) {
  Eigen::Quaterniond q(j[0].get<double>(), j[1].get<double>(), j[2].get<double>(), j[3].get<double>());
  if (std::abs(q.norm() - 1.0) > limits::kUnitQuaternionTolerance)
    fail(where, "rotation must be a unit quaternion [w, x, y, z]");
  return q;
}

template <class T>
T value_or(const json& obj, const char* key, T fallback) {
  const auto it = obj.find(key);
  return it == obj.end() ? fallback : it->get<T>();
}

json vec_json(const Vec3& v) {
  return json::array({v[0], v[1], v[2]});
}

// --- the defs' settings, one table per def ------------------------------------------------------
// A row is a setting's key in the scene format and its member in the core's struct, whose default
// initialiser is the setting's default. read_rows fills in the keys a document gives (the others
// keep their defaults); write_rows writes every row (unless its `saved` says the setting does not
// apply). Adding a setting to a def: its member (with its default) in the core's struct, one row
// here, its key in schemas/scene.schema.json, and its copy in the C ABI's table (capi/src).

/// One setting of the def S: its key and its member.
template <class S, class T>
struct Row {
  const char* key;
  T S::*member;
  bool (*saved)(const S&) = nullptr;  // null: always written
};
// Deduction guides for the aggregate (clang before 17, which builds the sanitizer runs, deduces no
// aggregate's arguments by itself).
template <class S, class T>
Row(const char*, T S::*) -> Row<S, T>;
template <class S, class T>
Row(const char*, T S::*, bool (*)(const S&)) -> Row<S, T>;

template <class T>
T value_of(const json& j) {
  if constexpr (std::is_same_v<T, Vec3>)
    return vec3(j);
  else if constexpr (std::is_same_v<T, Tolerance>)
    return Tolerance{j["target"].get<double>(), j["max"].get<double>()};
  else
    return j.get<T>();
}

json json_of(double v) {
  return v;
}
json json_of(int32_t v) {
  return v;
}
json json_of(bool v) {
  return v;
}
json json_of(const Vec3& v) {
  return vec_json(v);
}
json json_of(const Tolerance& t) {
  return json{{"target", t.target}, {"max", t.max}};
}

/// The settings `j` gives into `s` (a tuple of rows); the others keep their values.
template <class Rows, class S>
void read_rows(const Rows& rows, const json& j, S& s) {
  std::apply(
      [&](const auto&... row) {
        const auto read = [&](const auto& r) {
          const auto it = j.find(r.key);
          if (it != j.end()) s.*r.member = value_of<std::remove_cvref_t<decltype(s.*r.member)>>(*it);
        };
        (read(row), ...);
      },
      rows);
}

/// Every setting of `s` that applies into `out` (a tuple of rows).
template <class Rows, class S>
void write_rows(const Rows& rows, const S& s, json& out) {
  std::apply(
      [&](const auto&... row) {
        const auto write = [&](const auto& r) {
          if (r.saved == nullptr || r.saved(s)) out[r.key] = json_of(s.*r.member);
        };
        (write(row), ...);
      },
      rows);
}

constexpr std::tuple kSolverRows{Row{"dt", &Settings::dt},
                                 Row{"substeps", &Settings::substeps},
                                 Row{"iterations", &Settings::iterations},
                                 Row{"gravity", &Settings::gravity},
                                 Row{"damping", &Settings::damping},
                                 Row{"settle_speed", &Settings::settle_speed},
                                 Row{"tethers", &Settings::tethers},
                                 Row{"realign_passes", &Settings::realign_passes},
                                 Row{"chebyshev_rho_milli", &Settings::chebyshev_rho_milli},
                                 Row{"self_collision", &Settings::self_collision},
                                 Row{"chain_solve", &Settings::chain_solve},
                                 Row{"threads", &Settings::threads},
                                 Row{"global_solve", &Settings::global_solve}};

constexpr std::tuple kMaterialRows{Row{"mass", &Material::mass},
                                   Row{"density", &Material::density},
                                   Row{"stretch_compliance", &Material::stretch_compliance},
                                   Row{"shear_compliance", &Material::shear_compliance},
                                   Row{"bend_compliance", &Material::bend_compliance},
                                   Row{"volume_compliance", &Material::volume_compliance},
                                   Row{"damping", &Material::damping},
                                   Row{"thickness", &Material::thickness},
                                   Row{"friction_static", &Material::friction_static},
                                   Row{"friction_dynamic", &Material::friction_dynamic}};

constexpr std::tuple kGroupRows{Row{"order", &GroupDesc::order}, Row{"weight", &GroupDesc::weight},
                                Row{"enabled", &GroupDesc::enabled}};

/// A pin's particle (a number or a body's vertex) and group (a name) are read and written beside these.
constexpr std::tuple kPinRows{Row{"target", &PinDesc::target}, Row{"compliance", &PinDesc::compliance}};

/// A collider's shape, rotation, vertices and triangles are read and written beside these.
constexpr std::tuple kColliderRows{
    Row{"position", &ColliderDesc::position},
    Row{"radius", &ColliderDesc::radius,
        +[](const ColliderDesc& d) { return d.shape == ColliderShape::sphere || d.shape == ColliderShape::capsule; }},
    Row{"half_extents", &ColliderDesc::half_extents,
        +[](const ColliderDesc& d) { return d.shape == ColliderShape::box; }},
    Row{"half_length", &ColliderDesc::half_length,
        +[](const ColliderDesc& d) { return d.shape == ColliderShape::capsule; }},
    Row{"thickness", &ColliderDesc::thickness},
    Row{"friction_static", &ColliderDesc::friction_static},
    Row{"friction_dynamic", &ColliderDesc::friction_dynamic}};

constexpr std::tuple kWindRows{Row{"direction", &WindDesc::direction}, Row{"speed", &WindDesc::speed},
                               Row{"air_density", &WindDesc::air_density}, Row{"drag", &WindDesc::drag},
                               Row{"lift", &WindDesc::lift}};

constexpr std::tuple kPressureRows{
    Row{"inside_pressure", &PressureDesc::inside_pressure}, Row{"outside_pressure", &PressureDesc::outside_pressure},
    Row{"keep_volume", &PressureDesc::keep_volume}, Row{"volume_compliance", &PressureDesc::volume_compliance},
    Row{"rest_volume", &PressureDesc::rest_volume}};

constexpr std::tuple kSurfaceTensionRows{Row{"tension", &SurfaceTensionDesc::tension},
                                         Row{"regularisation", &SurfaceTensionDesc::regularisation}};

constexpr std::tuple kVortexRows{Row{"center", &VortexDesc::center},        Row{"axis", &VortexDesc::axis},
                                 Row{"strength", &VortexDesc::strength},    Row{"radius", &VortexDesc::radius},
                                 Row{"twist", &VortexDesc::twist},          Row{"decay", &VortexDesc::decay},
                                 Row{"start_time", &VortexDesc::start_time}};

/// The field kinds' names in the scene format, by FieldKind.
constexpr const char* kFieldKindNames[kFieldKindCount] = {"wind", "pressure", "surface_tension", "vortex"};

/// Calls `f(desc, rows)` with the settings of `d`'s kind and their table.
template <class D, class F>
void visit_field(D& d, F&& f) {
  switch (d.kind) {
    case FieldKind::wind:
      return f(d.wind, kWindRows);
    case FieldKind::pressure:
      return f(d.pressure, kPressureRows);
    case FieldKind::surface_tension:
      return f(d.surface_tension, kSurfaceTensionRows);
    case FieldKind::vortex:
      return f(d.vortex, kVortexRows);
  }
}

/// A generated panel mesh's settings (a saved scene keeps the body and layout it made instead).
constexpr std::tuple kPanelMeshRows{Row{"thickness", &PanelMeshDesc::thickness},
                                    Row{"mass", &PanelMeshDesc::mass},
                                    Row{"density", &PanelMeshDesc::density},
                                    Row{"damping", &PanelMeshDesc::damping},
                                    Row{"friction_static", &PanelMeshDesc::friction_static},
                                    Row{"friction_dynamic", &PanelMeshDesc::friction_dynamic},
                                    Row{"slide_compliance", &PanelMeshDesc::slide_compliance}};

/// The pin supports' names in the scene format, by PinSupport.
constexpr const char* kPinSupportNames[] = {"point", "plane", "line", "polyline", "axes", "mesh"};
static_assert(std::size(kPinSupportNames) == kPinSupportCount);

/// The area load modes' names in the scene format, by AreaLoadMode.
constexpr const char* kAreaLoadModeNames[] = {"normal", "true_area", "projected_area"};
static_assert(std::size(kAreaLoadModeNames) == kAreaLoadModeCount);

/// The panel pins' names in the scene format, by PanelPins.
constexpr const char* kPanelPinsNames[] = {"none", "top_corners", "top_and_bottom_corners"};
/// The panel corners' names in the scene format, by PanelCorners.
constexpr const char* kPanelCornersNames[] = {"welded", "shared"};
/// The panel rows' precisions' names in the scene format, by PanelPrecision.
constexpr const char* kPanelPrecisionNames[] = {"full", "single"};

/// The enumerator `o[key]` names in `names` (the schema has checked it is one of them), or `absent`
/// when `o` has no `key`.
template <class E, size_t N>
E named_enum(const json& o, const char* key, const char* const (&names)[N], E absent) {
  if (o.contains(key))
    for (size_t k = 0; k < N; ++k)
      if (o[key] == names[k]) return static_cast<E>(k);
  return absent;
}

constexpr std::tuple kTolerancesRows{Row{"unit_scale", &Tolerances::unit_scale},
                                     Row{"planarity", &Tolerances::planarity},
                                     Row{"planarity_distance", &Tolerances::planarity_distance},
                                     Row{"thickness", &Tolerances::thickness}, Row{"miter", &Tolerances::miter}};

/// A body's vertices, elements and named vertex sets before it becomes part of the world.
struct Mesh {
  std::vector<double> positions, uvs, masses;
  std::vector<int32_t> edges, triangles, tets;
  std::map<std::string, std::vector<int32_t>> sets;
};

void place(Mesh& m, const json& spec, const std::string& where) {
  const Vec3 origin = spec.contains("origin") ? vec3(spec["origin"]) : Vec3::Zero();
  const Eigen::Quaterniond q =
      spec.contains("rotation") ? quat(spec["rotation"], where + "/rotation") : Eigen::Quaterniond::Identity();
  for (size_t i = 0; i < m.positions.size(); i += 3) {
    const Vec3 p = origin + q * Vec3(m.positions[i], m.positions[i + 1], m.positions[i + 2]);
    for (int k = 0; k < 3; ++k) m.positions[i + k] = p[k];
  }
}

Mesh grid_mesh(const json& s) {
  Mesh m;
  const int nx = s["resolution"][0].get<int>(), ny = s["resolution"][1].get<int>();
  const double sx = s["size"][0].get<double>(), sy = s["size"][1].get<double>();
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double x = sx * (static_cast<double>(i) / (nx - 1) - 0.5),
                   y = sy * (static_cast<double>(j) / (ny - 1) - 0.5);
      m.positions.insert(m.positions.end(), {x, y, 0.0});
      m.uvs.insert(m.uvs.end(), {x, y});
    }
  auto at = [nx](int i, int j) { return j * nx + i; };
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      if ((i + j) % 2 == 0)
        m.triangles.insert(m.triangles.end(), {a, b, c, a, c, d});
      else
        m.triangles.insert(m.triangles.end(), {a, b, d, b, c, d});
    }
  m.sets["corners"] = {at(0, 0), at(nx - 1, 0), at(nx - 1, ny - 1), at(0, ny - 1)};
  for (int j = 0; j < ny; ++j) {
    m.sets["edge_x0"].push_back(at(0, j));
    m.sets["edge_x1"].push_back(at(nx - 1, j));
  }
  for (int i = 0; i < nx; ++i) {
    m.sets["edge_y0"].push_back(at(i, 0));
    m.sets["edge_y1"].push_back(at(i, ny - 1));
  }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      if (i == 0 || j == 0 || i == nx - 1 || j == ny - 1) m.sets["boundary"].push_back(at(i, j));
  return m;
}

Mesh triangle_mesh(const json& s) {
  Mesh m;
  const int rows = s["rows"].get<int>();
  const double side = s["side"].get<double>();
  const double h = side * std::sqrt(3.0) / 2.0;
  auto at = [rows](int r, int c) { return r * (rows + 1) - (r * (r - 1)) / 2 + c; };
  for (int r = 0; r <= rows; ++r)
    for (int c = 0; c <= rows - r; ++c) {
      const double x = side * (c + 0.5 * r) / rows - side / 2, y = h * r / rows - h / 3;
      m.positions.insert(m.positions.end(), {x, y, 0.0});
      m.uvs.insert(m.uvs.end(), {x, y});
      if (r == 0 || c == 0 || c == rows - r) m.sets["boundary"].push_back(at(r, c));
    }
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < rows - r; ++c) {
      m.triangles.insert(m.triangles.end(), {at(r, c), at(r, c + 1), at(r + 1, c)});
      if (c + 1 < rows - r) m.triangles.insert(m.triangles.end(), {at(r, c + 1), at(r + 1, c + 1), at(r + 1, c)});
    }
  m.sets["corners"] = {at(0, 0), at(0, rows), at(rows, 0)};
  return m;
}

Mesh tube_mesh(const json& s) {
  Mesh m;
  const int seg = s["segments"].get<int>(), rings = s["rings"].get<int>();
  const double radius = s["radius"].get<double>(), length = s["length"].get<double>();
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < seg; ++k) {
      const double t = 2.0 * std::numbers::pi * k / seg, z = length * (static_cast<double>(r) / (rings - 1) - 0.5);
      m.positions.insert(m.positions.end(), {radius * std::cos(t), radius * std::sin(t), z});
      m.uvs.insert(m.uvs.end(), {radius * t, z});
      if (r == 0) m.sets["ring0"].push_back(r * seg + k);
      if (r == rings - 1) m.sets["ring1"].push_back(r * seg + k);
      if (r == 0 || r == rings - 1) m.sets["boundary"].push_back(r * seg + k);
    }
  for (int r = 0; r + 1 < rings; ++r)
    for (int k = 0; k < seg; ++k) {
      const int a = r * seg + k, b = r * seg + (k + 1) % seg, c = b + seg, d = a + seg;
      if ((r + k) % 2 == 0)
        m.triangles.insert(m.triangles.end(), {a, b, c, a, c, d});
      else
        m.triangles.insert(m.triangles.end(), {a, b, d, b, c, d});
    }
  // A seam-crossing uv jump would misread the edge's direction: u is periodic, so measure it
  // the short way round by leaving uvs out of the seam's direction split.
  return m;
}

/// The closed generators (closed_meshes.hpp).
Mesh closed_mesh(const json& s, const std::string& where) {
  SurfaceMesh surface;
  if (s["generator"] == "icosphere") {
    surface = icosphere(s["radius"].get<double>(), s["subdivisions"].get<int>());
  } else {
    const std::array<double, 3> size{s["size"][0].get<double>(), s["size"][1].get<double>(),
                                     s["size"][2].get<double>()};
    const double radius = value_or(s, "radius", 0.0);
    if (2.0 * radius > std::min({size[0], size[1], size[2]}))
      fail(where + "/radius", "the rounding radius exceeds half the box's smallest extent");
    surface = rounded_box(size, radius, s["resolution"].get<int>());
  }
  Mesh m;
  m.positions = std::move(surface.positions);
  m.triangles = std::move(surface.triangles);
  m.sets = std::move(surface.sets);
  return m;
}

/// The file an OBJ path names, read whole: resolved against options.base_dir (unless absolute) and,
/// unless options.allow_paths_outside_base, refused when absolute or when it resolves (following
/// symbolic links and "..") outside base_dir; refused unless a regular file (no folder, device or
/// pipe: it is opened without blocking and checked before a byte is read) of at most
/// limits::kMaxObjBytes, a bound the reading keeps too. Errors name `where` and the path as the
/// scene gives it (JSON-quoted), never the file's content.
std::string read_obj_file(const std::string& rel, const LoadOptions& options, const std::string& where,
                          std::string& shown) {
  namespace fs = std::filesystem;
  shown = "OBJ file " + json(rel).dump(-1, ' ', true);
  const fs::path given = path_from_utf8(rel);
  const fs::path base = path_from_utf8(options.base_dir.empty() ? "." : options.base_dir);
  // On Windows "\x" (the current drive's root) and "C:x" are not absolute, yet not inside either.
  const bool absolute = given.is_absolute() || given.has_root_path();
  fs::path path = absolute ? given : base / given;
  if (!options.allow_paths_outside_base) {
    if (absolute) fail(where, shown + ": an absolute path is refused: OBJ paths are relative to the scene's folder");
    std::error_code ec;
    const fs::path root = fs::canonical(base, ec);
    if (ec)
      fail(where, "cannot open " + shown + " (" + utf8_from_path(path) + "): the scene's folder: " + ec.message());
    const fs::path resolved = fs::weakly_canonical(path, ec);
    if (ec) fail(where, "cannot open " + shown + " (" + utf8_from_path(path) + "): " + ec.message());
    // Inside: the folder's components are the first of the file's (both canonical, no "..").
    const bool inside = std::distance(root.begin(), root.end()) <= std::distance(resolved.begin(), resolved.end()) &&
                        std::mismatch(root.begin(), root.end(), resolved.begin()).first == root.end();
    if (!inside)
      fail(where, shown +
                      " leads outside the scene's folder (by \"..\" or a symbolic link): refused unless the "
                      "host allows paths outside it");
    path = resolved;
  }
  std::string text, error;
  if (!read_regular_file(utf8_from_path(path), limits::kMaxObjBytes, text, error))
    fail(where, shown + (error.starts_with("could not") ? " (" + utf8_from_path(path) + ")" : "") + " " + error);
  return text;
}

/// Reads the OBJ file named by s["obj"] (read_obj_file; vertices scaled by s["scale"]): its
/// vertices into `positions`, at most `max_vertices` of them, and every face (0-based vertex
/// indices) to `on_face(face, at)` with `at` the "OBJ file "...": line N: " it came from. Errors
/// name the JSON pointer `where`/obj and the line, never the file's content. Returns how the
/// messages name the file.
template <class OnFace>
std::string read_obj(const json& s, const LoadOptions& options, const std::string& where, int64_t max_vertices,
                     std::vector<double>& positions, OnFace&& on_face) {
  std::string shown;
  const std::string text = read_obj_file(s["obj"].get<std::string>(), options, where + "/obj", shown);
  const double scale = value_or(s, "scale", 1.0);
  int64_t line_no = 0;
  std::vector<int32_t> face;
  for (size_t begin = 0; begin < text.size();) {
    size_t stop = text.find('\n', begin);
    if (stop == std::string::npos) stop = text.size();
    std::istringstream ls(text.substr(begin, stop - begin));
    begin = stop + 1;
    ++line_no;
    std::string tag;
    ls >> tag;
    const std::string at = shown + ": line " + std::to_string(line_no) + ": ";
    if (tag == "v") {
      double x, y, z;
      if (!(ls >> x >> y >> z) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
        fail(where + "/obj", at + "a vertex needs three finite numbers");
      if (static_cast<int64_t>(positions.size() / 3) >= max_vertices)
        fail(where + "/obj", at + "more than " + std::to_string(max_vertices) +
                                 " vertices, the most there is room for (a world holds at most " +
                                 std::to_string(limits::kMaxParticles) + " particles, EMBRA_MAX_PARTICLES)");
      positions.insert(positions.end(), {scale * x, scale * y, scale * z});
    } else if (tag == "f") {
      face.clear();
      std::string token;
      const long n = static_cast<long>(positions.size() / 3);
      while (ls >> token) {
        long v = 0;
        try {
          v = std::stol(token.substr(0, token.find('/')));
        } catch (const std::exception&) {
          fail(where + "/obj", at + "bad face index");
        }
        if (v < 0) v = n + v + 1;  // OBJ's relative indices
        if (v < 1 || v > n)
          fail(where + "/obj", at + "a face index is outside the " + std::to_string(n) + " vertices before it");
        face.push_back(static_cast<int32_t>(v - 1));
      }
      on_face(face, at);
    }
  }
  return shown;
}

/// Room left in `w` for a body of `vertices` vertices and `triangles` triangles, checked before the
/// body is generated: the bounds World::create_body applies (limits.hpp: particles, and constraints
/// counted as it counts them, six per triangle: a stretch, a shear and a bend per triangle edge).
void check_room(const World& w, int64_t vertices, int64_t triangles, const std::string& where,
                const std::string& what) {
  if (vertices > limits::kMaxParticles - w.particle_count())
    fail(where, what + " has " + std::to_string(vertices) + " vertices: a world holds at most " +
                    std::to_string(limits::kMaxParticles) + " particles (EMBRA_MAX_PARTICLES) and has " +
                    std::to_string(w.particle_count()));
  if (6 * triangles > limits::kMaxConstraints - w.constraint_count())
    fail(where, what + " has " + std::to_string(triangles) + " triangles, which could generate " +
                    std::to_string(6 * triangles) + " constraints: a world holds at most " +
                    std::to_string(limits::kMaxConstraints) + " (EMBRA_MAX_CONSTRAINTS) and has " +
                    std::to_string(w.constraint_count()));
}

/// The vertices and triangles a generator makes, checked against the room in `w` before it runs.
void check_generator_room(const World& w, const json& s, const std::string& at) {
  const std::string gen = s["generator"].get<std::string>();
  int64_t nv = 0, nt = 0;
  std::string key, what;
  if (gen == "grid") {
    const int64_t nx = s["resolution"][0].get<int64_t>(), ny = s["resolution"][1].get<int64_t>();
    nv = nx * ny;
    nt = 2 * (nx - 1) * (ny - 1);
    key = "/resolution";
    what = "a " + std::to_string(nx) + " x " + std::to_string(ny) + " grid";
  } else if (gen == "triangle") {
    const int64_t r = s["rows"].get<int64_t>();
    nv = (r + 1) * (r + 2) / 2;
    nt = r * r;
    key = "/rows";
    what = "a triangle of " + std::to_string(r) + " rows";
  } else if (gen == "tube") {
    const int64_t seg = s["segments"].get<int64_t>(), rings = s["rings"].get<int64_t>();
    nv = seg * rings;
    nt = 2 * seg * (rings - 1);
    what = "a tube of " + std::to_string(seg) + " segments x " + std::to_string(rings) + " rings";
  } else if (gen == "icosphere") {
    const int64_t n = int64_t{1} << (2 * s["subdivisions"].get<int>());  // 4^subdivisions
    nv = 10 * n + 2;
    nt = 20 * n;
    key = "/subdivisions";
    what = "an icosphere of " + std::to_string(s["subdivisions"].get<int>()) + " subdivisions";
  } else {  // rounded_box: the lattice points on a cube's surface, two triangles per face square
    const int64_t n = s["resolution"].get<int64_t>();
    nv = 6 * n * n + 2;
    nt = 12 * n * n;
    key = "/resolution";
    what = "a rounded box of resolution " + std::to_string(n);
  }
  check_room(w, nv, nt, at + key, what);
}

Mesh obj_mesh(const World& w, const json& s, const LoadOptions& options, const std::string& where) {
  Mesh m;
  const int64_t max_triangles = (limits::kMaxConstraints - w.constraint_count()) / 6;
  const std::string shown = read_obj(s, options, where, limits::kMaxParticles - w.particle_count(), m.positions,
                                     [&](const std::vector<int32_t>& face, const std::string& at) {
                                       if (face.size() < 3) fail(where + "/obj", at + "a face needs 3 vertices");
                                       for (size_t k = 1; k + 1 < face.size(); ++k)
                                         m.triangles.insert(m.triangles.end(), {face[0], face[k], face[k + 1]});
                                       if (static_cast<int64_t>(m.triangles.size() / 3) > max_triangles)
                                         check_room(w, 0, static_cast<int64_t>(m.triangles.size() / 3), where + "/obj",
                                                    at + "the file so far");
                                     });
  if (m.positions.empty()) fail(where + "/obj", shown + " has no vertices");
  return m;
}

Mesh inline_mesh(const json& s) {
  Mesh m;
  for (const json& v : s["vertices"])
    for (int k = 0; k < 3; ++k) m.positions.push_back(v[k].get<double>());
  auto ints = [&](const char* key, std::vector<int32_t>& out) {
    if (!s.contains(key)) return;
    for (const json& e : s[key])
      for (const json& i : e) {
        if (i.get<int64_t>() > INT32_MAX) fail(std::string("/") + key, "index too large");
        out.push_back(i.get<int32_t>());
      }
  };
  ints("edges", m.edges);
  ints("triangles", m.triangles);
  ints("tets", m.tets);
  if (s.contains("uvs"))
    for (const json& uv : s["uvs"]) m.uvs.insert(m.uvs.end(), {uv[0].get<double>(), uv[1].get<double>()});
  if (s.contains("masses"))
    for (const json& w : s["masses"]) m.masses.push_back(w.get<double>());
  return m;
}

Material material(const json& j) {
  Material m;
  if (!j.is_null()) read_rows(kMaterialRows, j, m);
  return m;
}

json material_json(const Material& m) {
  json out = json::object();
  write_rows(kMaterialRows, m, out);
  return out;
}

const char* const kGenerateNames[] = {"stretch", "shear", "bend", "volume"};

/// Builds the world from a validated document, section by section; every error names its place.
class Builder {
 public:
  Builder(const json& doc, const LoadOptions& options, SceneMeta& meta) : doc_(doc), options_(options), meta_(meta) {}

  std::unique_ptr<World> build() {
    Settings s;
    if (doc_.contains("solver")) {
      // "preset": "form_finding" (the schema's only value) starts from the preset; the keys override it.
      if (doc_["solver"].contains("preset")) s = form_finding_settings();
      read_rows(kSolverRows, doc_["solver"], s);
    }
    auto world = guard("/solver", [&] { return std::make_unique<World>(s); });
    World& w = *world;
    meta_.name = value_or(doc_, "name", std::string());
    meta_.description = value_or(doc_, "description", std::string());
    meta_.frames = value_or(doc_, "frames", meta_.frames);
    groups_["default"] = w.default_group();
    groups_["contacts"] = w.contact_group();
    meta_.group_names[w.default_group().index] = "default";
    meta_.group_names[w.contact_group().index] = "contacts";
    section("groups", [&](const json& g, const std::string& at) {
      const std::string name = g["name"].get<std::string>();
      GroupDesc d;
      read_rows(kGroupRows, g, d);
      d.name = name;
      const auto it = groups_.find(name);
      if (it != groups_.end()) {
        if (!seen_groups_.insert(name).second) fail(at + "/name", "group '" + name + "' is listed twice");
        guard(at, [&] {
          w.set_group_order(it->second, d.order);
          w.set_group_weight(it->second, d.weight);
          w.set_group_enabled(it->second, d.enabled);
          return 0;
        });
        return;
      }
      seen_groups_.insert(name);
      const Id id = guard(at, [&] { return w.create_group(d); });
      groups_[name] = id;
      meta_.group_names[id.index] = name;
    });
    section("bodies", [&](const json& b, const std::string& at) { body(w, b, at); });
    section("panel_meshes", [&](const json& p, const std::string& at) { panel_mesh(w, p, at); });
    section("constraints", [&](const json& c, const std::string& at) { constraints(w, c, at); });
    if (doc_.contains("state")) state(w, doc_["state"]);
    section("pins", [&](const json& p, const std::string& at) { pins(w, p, at); });
    section("loads", [&](const json& l, const std::string& at) { load(w, l, at); });
    std::vector<AreaLoad> area_loads;
    section("area_loads", [&](const json& l, const std::string& at) {
      AreaLoad a;
      for (int k = 0; k < 3; ++k)
        a.particles[k] = particle(w, l["particles"][k], at + "/particles/" + std::to_string(k));
      a.mode = named_enum(l, "mode", kAreaLoadModeNames, a.mode);
      a.pressure = l["pressure"].get<double>();
      if (l.contains("direction")) a.direction = vec3(l["direction"]);
      guard(at, [&] {
        w.check_area_load(a, "area load");
        return 0;
      });
      area_loads.push_back(a);
    });
    guard("/area_loads", [&] {
      w.set_area_loads(area_loads);
      return 0;
    });
    std::vector<LineLoad> line_loads;
    section("line_loads", [&](const json& l, const std::string& at) {
      LineLoad a;
      for (int k = 0; k < 2; ++k)
        a.particles[k] = particle(w, l["particles"][k], at + "/particles/" + std::to_string(k));
      a.load = vec3(l["load"]);
      guard(at, [&] {
        w.check_line_load(a, "line load");
        return 0;
      });
      line_loads.push_back(a);
    });
    guard("/line_loads", [&] {
      w.set_line_loads(line_loads);
      return 0;
    });
    section("shape_matches", [&](const json& m, const std::string& at) {
      std::vector<int32_t> ids;
      for (size_t k = 0; k < m["particles"].size(); ++k)
        ids.push_back(particle(w, m["particles"][k], at + "/particles/" + std::to_string(k)));
      std::vector<Vec3> rest;
      if (m.contains("rest"))
        for (const json& r : m["rest"]) rest.push_back(vec3(r));
      const Id g = group(m, "group", at);
      guard(at, [&] { return w.add_shape_match(g, ids, rest, m["compliance"].get<double>()); });
    });
    section("colliders", [&](const json& c, const std::string& at) {
      ColliderDesc d;
      d.shape = collider_shape(c["shape"].get<std::string>());
      if (c.contains("rotation")) d.rotation = quat(c["rotation"], at + "/rotation");
      read_rows(kColliderRows, c, d);
      if (c.contains("vertices"))
        for (const json& v : c["vertices"])
          for (const json& k : v) d.vertices.push_back(k.get<double>());
      if (c.contains("triangles"))
        for (const json& t : c["triangles"])
          for (const json& k : t) d.triangles.push_back(k.get<int32_t>());
      // A collider moved since the last step is created at its pose at the start of the frame and
      // then moved, so the next step sweeps it as the world saved would have.
      const json* start = c.contains("name") ? frame_start_pose(c["name"].get<std::string>()) : nullptr;
      const Vec3 position = d.position;
      const Eigen::Quaterniond rotation = d.rotation;
      if (start != nullptr) {
        d.position = vec3((*start)["position"]);
        d.rotation = quat((*start)["rotation"], "/state/colliders");
      }
      const Id id = guard(at, [&] { return w.create_collider(d); });
      if (start != nullptr) guard(at, [&] { w.set_collider_transform(id, position, rotation); });
      if (c.contains("name")) name_once(colliders_, meta_.collider_names, c["name"], id, at, "collider");
    });
    if (doc_.contains("state") && doc_["state"].contains("colliders"))
      for (size_t i = 0; i < doc_["state"]["colliders"].size(); ++i)
        if (!frame_starts_used_.contains(i))
          fail("/state/colliders/" + std::to_string(i) + "/collider", "names no collider of the scene");
    section("fields", [&](const json& f, const std::string& at) { field(w, f, at); });
    section("actions", [&](const json& a, const std::string& at) { action(a, at); });
    if (doc_.contains("tolerances")) meta_.tolerances = doc_["tolerances"].dump();
    // Last: the forces name groups, pins and colliders, and count the constraints and tethers of
    // the world as built.
    if (doc_.contains("state") && doc_["state"].contains("forces")) forces(w, doc_["state"]["forces"]);
    return world;
  }

 private:
  /// The pose at the start of the frame that /state/colliders gives the collider `name`, or null.
  /// An entry naming no collider of the scene is refused once the colliders are built.
  const json* frame_start_pose(const std::string& name) {
    if (!doc_.contains("state") || !doc_["state"].contains("colliders")) return nullptr;
    const json& list = doc_["state"]["colliders"];
    const json* found = nullptr;
    for (size_t i = 0; i < list.size(); ++i)
      if (list[i]["collider"].get<std::string>() == name) {
        if (found != nullptr)
          fail("/state/colliders/" + std::to_string(i) + "/collider", "names collider \"" + name + "\" again");
        found = &list[i];
        frame_starts_used_.insert(i);
      }
    return found;
  }

  template <class F>
  auto guard(const std::string& at, F&& f) -> decltype(f()) {
    try {
      return f();
    } catch (const Error& e) {
      fail(at, e.what());
    }
  }

  template <class F>
  void section(const char* key, F&& per_item) {
    if (!doc_.contains(key)) return;
    const json& list = doc_[key];
    for (size_t i = 0; i < list.size(); ++i) per_item(list[i], std::string("/") + key + "/" + std::to_string(i));
  }

  static void name_once(std::map<std::string, Id>& names, std::map<uint32_t, std::string>& by_slot, const json& name,
                        Id id, const std::string& at, const char* what) {
    const std::string n = name.get<std::string>();
    if (!names.emplace(n, id).second) fail(at + "/name", std::string(what) + " name '" + n + "' is used twice");
    by_slot[id.index] = n;
  }

  Id group(const json& obj, const char* key, const std::string& at) {
    if (!obj.contains(key)) return Id{};
    const std::string n = obj[key].get<std::string>();
    const auto it = groups_.find(n);
    if (it == groups_.end()) fail(at + "/" + key, "no group named '" + n + "'");
    return it->second;
  }

  Id named(const std::map<std::string, Id>& names, const json& obj, const char* key, const std::string& at) {
    if (!obj.contains(key)) fail(at, std::string("needs \"") + key + "\"");
    const std::string n = obj[key].get<std::string>();
    const auto it = names.find(n);
    if (it == names.end()) fail(at + "/" + key, std::string("no ") + key + " named '" + n + "'");
    return it->second;
  }

  void body(World& w, const json& b, const std::string& at) {
    const json& spec = b["mesh"];
    Mesh m;
    if (spec.contains("vertices")) {
      m = inline_mesh(spec);
    } else if (spec.contains("obj")) {
      m = obj_mesh(w, spec, options_, at + "/mesh");
    } else {
      check_generator_room(w, spec, at + "/mesh");  // before a byte of it is generated
      if (spec["generator"] == "grid")
        m = grid_mesh(spec);
      else if (spec["generator"] == "triangle")
        m = triangle_mesh(spec);
      else if (spec["generator"] == "tube")
        m = tube_mesh(spec);
      else
        m = closed_mesh(spec, at + "/mesh");
    }
    if (!spec.contains("vertices")) place(m, spec, at + "/mesh");
    const int64_t nv = static_cast<int64_t>(m.positions.size() / 3);
    if (!m.uvs.empty() && static_cast<int64_t>(m.uvs.size()) != 2 * nv)
      fail(at + "/mesh/uvs", "needs one [u, v] per vertex");
    if (!m.masses.empty() && static_cast<int64_t>(m.masses.size()) != nv)
      fail(at + "/mesh/masses", "needs one mass per vertex");
    if (b.contains("vertex_sets"))
      for (const auto& [name, list] : b["vertex_sets"].items()) {
        std::vector<int32_t> set;
        for (const json& v : list) {
          if (v.get<int64_t>() >= nv)
            fail(at + "/vertex_sets/" + name,
                 "vertex " + v.dump() + " is outside the body's " + std::to_string(nv) + " vertices");
          set.push_back(v.get<int32_t>());
        }
        m.sets[name] = set;
      }
    BodyDesc d;
    d.positions = m.positions;
    d.masses = m.masses;
    d.uvs = m.uvs;
    d.edges = m.edges;
    d.triangles = m.triangles;
    d.tets = m.tets;
    d.material = material(b.contains("material") ? b["material"] : json());
    if (b.contains("generate")) {
      d.generate = 0;
      for (const json& g : b["generate"])
        for (uint32_t k = 0; k < 4; ++k)
          if (g == kGenerateNames[k]) d.generate |= 1u << k;
    }
    d.stretch_group = group(b, "stretch_group", at);
    d.shear_group = group(b, "shear_group", at);
    d.bend_group = group(b, "bend_group", at);
    d.volume_group = group(b, "volume_group", at);
    const Id id = guard(at + "/mesh", [&] { return w.create_body(d); });
    name_once(bodies_, meta_.body_names, b["name"], id, at, "body");
    sets_[id.index] = std::move(m.sets);
    if (b.contains("rest_scale")) {
      const json& s = b["rest_scale"];
      guard(at + "/rest_scale", [&] {
        w.set_rest_scale(id, s[0].get<double>(), s[1].get<double>(), s[2].get<double>());
        return 0;
      });
    }
  }

  int32_t particle(const World& w, const json& ref, const std::string& at) {
    if (ref.is_number_integer()) {
      const int64_t i = ref.get<int64_t>();
      if (i >= w.particle_count())
        fail(at, "particle " + std::to_string(i) + " is outside the world's " + std::to_string(w.particle_count()) +
                     " particles");
      return static_cast<int32_t>(i);
    }
    const Id body = named(bodies_, ref, "body", at);
    const BodyInfo& info = w.body(body);
    const int64_t v = ref["vertex"].get<int64_t>();
    if (v >= info.particle_count)
      fail(at + "/vertex", "vertex " + std::to_string(v) + " is outside body '" + ref["body"].get<std::string>() +
                               "' (" + std::to_string(info.particle_count) + " vertices)");
    return info.first_particle + static_cast<int32_t>(v);
  }

  void constraints(World& w, const json& c, const std::string& at) {
    const std::string kind = c["kind"].get<std::string>();
    const Kind k = *kind_from_name(kind);  // the schema has checked it names a kind
    const int n = arity(k);
    std::vector<int32_t> ids;
    const json& list = c["particles"];
    for (size_t i = 0; i < list.size(); ++i) {
      const std::string where = at + "/particles/" + std::to_string(i);
      if (static_cast<int>(list[i].size()) != n)
        fail(where, "a " + kind + " constraint takes " + std::to_string(n) + " particles, not " +
                        std::to_string(list[i].size()));
      for (size_t a = 0; a < list[i].size(); ++a)
        ids.push_back(particle(w, list[i][a], where + "/" + std::to_string(a)));
    }
    std::vector<double> rest, compliance;
    if (c.contains("rest") && c["rest"].is_array()) {
      for (const json& r : c["rest"]) rest.push_back(r.get<double>());
      if (rest.size() != list.size())
        fail(at + "/rest",
             "has " + std::to_string(rest.size()) + " values for " + std::to_string(list.size()) + " constraints");
    }
    ConstraintDesc d;
    d.kind = k;
    d.group = group(c, "group", at);
    d.particles = ids;
    d.rest = rest;
    if (c.contains("compliance") && c["compliance"].is_array()) {
      for (const json& v : c["compliance"]) compliance.push_back(v.get<double>());
      if (compliance.size() != list.size())
        fail(at + "/compliance", "has " + std::to_string(compliance.size()) + " values for " +
                                     std::to_string(list.size()) + " constraints");
      d.compliance = compliance;
    } else {
      d.uniform_compliance = value_or(c, "compliance", d.uniform_compliance);
    }
    // Plasticity and rupture: one value for all, or one per constraint; 0 (none) when left out.
    const auto per_constraint = [&](const char* key) {
      std::vector<double> v(list.size(), 0.0);
      if (!c.contains(key)) return v;
      if (!c[key].is_array()) return std::vector<double>(list.size(), c[key].get<double>());
      if (c[key].size() != list.size())
        fail(at + "/" + key,
             "has " + std::to_string(c[key].size()) + " values for " + std::to_string(list.size()) + " constraints");
      for (size_t i = 0; i < list.size(); ++i) v[i] = c[key][i].get<double>();
      return v;
    };
    const std::vector<double> yield = per_constraint("yield"), rupture = per_constraint("rupture");
    const int64_t before = w.constraint_count(d.group, k).first;
    guard(at, [&] { return w.add_constraints(d); });
    for (size_t i = 0; i < list.size(); ++i)
      if (yield[i] != 0.0 || rupture[i] != 0.0)
        guard(at + (yield[i] != 0.0 ? "/yield" : "/rupture"), [&] {
          w.set_constraint_plasticity(d.group, k, before + static_cast<int64_t>(i), yield[i], rupture[i]);
          return 0;
        });
  }

  void state(World& w, const json& s) {
    const json& x = s["positions"];
    const json& v = s["velocities"];
    if (static_cast<int64_t>(x.size()) != w.particle_count())
      fail("/state/positions",
           "has " + std::to_string(x.size()) + " positions for " + std::to_string(w.particle_count()) + " particles");
    if (static_cast<int64_t>(v.size()) != w.particle_count())
      fail("/state/velocities",
           "has " + std::to_string(v.size()) + " velocities for " + std::to_string(w.particle_count()) + " particles");
    std::vector<double> xs, vs;
    for (const json& p : x)
      for (int k = 0; k < 3; ++k) xs.push_back(p[k].get<double>());
    for (const json& p : v)
      for (int k = 0; k < 3; ++k) vs.push_back(p[k].get<double>());
    guard("/state", [&] {
      w.set_positions(0, xs);
      w.set_velocities(0, vs);
      w.set_clock(s["frame"].get<int64_t>(), value_or(s, "time", 0.0));
      return 0;
    });
  }

  /// /state/forces: the multipliers and contact forces the force readers read (World::set_statics_state).
  void forces(World& w, const json& f) {
    const std::string at = "/state/forces";
    StaticsState s;
    const auto each = [&](const char* key, const auto& per_item) {
      if (!f.contains(key)) return;
      for (size_t i = 0; i < f[key].size(); ++i) per_item(f[key][i], at + "/" + key + "/" + std::to_string(i));
    };
    const auto numbers = [](const json& list) {
      std::vector<double> out;
      out.reserve(list.size());
      for (const json& v : list) out.push_back(v.get<double>());
      return out;
    };
    each("constraints", [&](const json& c, const std::string& where) {
      StaticsState::Multipliers m;
      m.group = group(c, "group", where);
      m.kind = *kind_from_name(c["kind"].get<std::string>());  // the schema has checked it names a kind
      m.lambda = numbers(c["multipliers"]);
      const int64_t count = w.constraint_count(m.group, m.kind).first;
      const int64_t per = multipliers(m.kind);
      if (static_cast<int64_t>(m.lambda.size()) != per * count)
        fail(where + "/multipliers", "has " + std::to_string(m.lambda.size()) + " multipliers for the " +
                                         std::to_string(count) + " " + kind_name(m.kind) + " constraints of group '" +
                                         c["group"].get<std::string>() + "' (" + std::to_string(per) + " each)");
      s.constraints.push_back(std::move(m));
    });
    each("tethers", [&](const json& t, const std::string& where) {
      s.tethers.push_back({group(t, "group", where), numbers(t["multipliers"])});
    });
    each("pins", [&](const json& p, const std::string& where) {
      s.pins.push_back({named(pins_, p, "pin", where), vec3(p["multiplier"])});
    });
    each("contacts", [&](const json& c, const std::string& where) {
      Contact ct{};
      ct.particle = particle(w, c["particle"], where + "/particle");
      ct.collider = static_cast<int32_t>(named(colliders_, c, "collider", where).index);
      ct.force_h2 = vec3(c["force_h2"]);
      s.contacts.push_back(ct);
    });
    each("face_contacts", [&](const json& c, const std::string& where) {
      FaceContact fc{};
      for (int k = 0; k < 3; ++k) fc.ids[k] = particle(w, c["particles"][k], where + "/particles/" + std::to_string(k));
      fc.collider = static_cast<int32_t>(named(colliders_, c, "collider", where).index);
      fc.force_h2 = vec3(c["force_h2"]);
      s.face_contacts.push_back(fc);
    });
    guard(at, [&] {
      w.set_statics_state(s);
      return 0;
    });
  }

  /// A panel mesh: generated (grid, inline quads or an OBJ of quads) through build_panel_mesh, as a C
  /// host would; or, as a saved scene writes it, the layout of a body listed in "bodies" whose
  /// constraints and pins are listed in their own sections.
  void panel_mesh(World& w, const json& p, const std::string& at) {
    if (!p.contains("generator")) {
      PanelLayout l;
      l.body = named(bodies_, p, "body", at);
      l.vertex_count = p["vertex_count"].get<int32_t>();
      for (const json& q : p["quads"])
        for (const json& v : q) l.quads.push_back(v.get<int32_t>());
      l.thickness = p["thickness"].get<double>();
      l.shared = named_enum(p, "corners", kPanelCornersNames, PanelCorners::welded) == PanelCorners::shared;
      l.single = named_enum(p, "precision", kPanelPrecisionNames, PanelPrecision::full) == PanelPrecision::single;
      guard(at, [&] {
        w.set_panel_layout(l);
        return 0;
      });
      return;
    }
    std::vector<double> positions;
    std::vector<int32_t> quads;
    const std::string gen = p["generator"].get<std::string>();
    if (gen == "grid") {
      const Vec3 origin = p.contains("origin") ? vec3(p["origin"]) : Vec3::Zero();
      guard(at, [&] {
        panel_grid(p["columns"].get<int32_t>(), p["rows"].get<int32_t>(), p["panel_size"].get<double>(), origin,
                   positions, quads);
        return 0;
      });
    } else if (gen == "mesh") {
      for (const json& v : p["vertices"])
        for (const json& c : v) positions.push_back(c.get<double>());
      for (const json& q : p["quads"])
        for (const json& v : q) quads.push_back(v.get<int32_t>());
    } else {  // "obj": a quad mesh file
      // Each panel becomes 8 particles: the file is refused at the first panel the world has no room for.
      const int64_t max_panels = (limits::kMaxParticles - w.particle_count()) / 8;
      const std::string shown =
          read_obj(p, options_, at, limits::kMaxParticles, positions,
                   [&](const std::vector<int32_t>& face, const std::string& line) {
                     if (face.size() != 4) fail(at + "/obj", line + "a panel mesh's faces must be quads (4 vertices)");
                     if (static_cast<int64_t>(quads.size() / 4) >= max_panels)
                       fail(at + "/obj",
                            line + "more than " + std::to_string(max_panels) +
                                " panels, the most the world has room for (8 particles each; a world holds at most " +
                                std::to_string(limits::kMaxParticles) + " particles, EMBRA_MAX_PARTICLES)");
                     quads.insert(quads.end(), face.begin(), face.end());
                   });
      if (positions.empty() || quads.empty()) fail(at + "/obj", shown + " has no quads");
    }
    PanelMeshDesc d;
    d.positions = positions;
    d.quads = quads;
    read_rows(kPanelMeshRows, p, d);
    if (doc_.contains("tolerances")) d.tolerances = parse_tolerances(doc_["tolerances"].dump());
    d.pins = named_enum(p, "pins", kPanelPinsNames, d.pins);
    d.corners = named_enum(p, "corners", kPanelCornersNames, d.corners);
    d.precision = named_enum(p, "precision", kPanelPrecisionNames, d.precision);
    d.group = group(p, "group", at);
    std::vector<bool> had(w.pins().size());
    for (size_t i = 0; i < w.pins().size(); ++i) had[i] = w.pins()[i].alive;
    const Id id = guard(at, [&] { return build_panel_mesh(w, d); });
    name_once(bodies_, meta_.body_names, p["name"], id, at, "body");
    // The corner pins it made, named <name>.pin0, .pin1, ... in creation order.
    const std::string base = p["name"].get<std::string>();
    int k = 0;
    for (uint32_t i = 0; i < w.pins().size(); ++i)
      if (w.pins()[i].alive && (i >= had.size() || !had[i]))
        name_once(pins_, meta_.pin_names, json(base + ".pin" + std::to_string(k++)), Id{i, w.pins()[i].generation}, at,
                  "pin");
  }

  /// The particles of a pin or load: its "particle", or every vertex of its body's named "set".
  std::vector<int32_t> particles_of(const World& w, const json& p, const std::string& at) {
    std::vector<int32_t> particles;
    if (p.contains("particle")) {
      if (p.contains("body") || p.contains("set")) fail(at, "give either \"particle\" or \"body\" and \"set\"");
      particles.push_back(particle(w, p["particle"], at + "/particle"));
    } else {
      const Id body = named(bodies_, p, "body", at);
      const auto& sets = sets_[body.index];
      const std::string set = p["set"].get<std::string>();
      const auto it = sets.find(set);
      if (it == sets.end())
        fail(at + "/set", "body '" + p["body"].get<std::string>() + "' has no vertex set '" + set + "'");
      for (int32_t v : it->second) particles.push_back(w.body(body).first_particle + v);
    }
    return particles;
  }

  /// A point load on each of its particles, added to what earlier loads put there. A particle's
  /// first load is taken as written, so a saved world's -0.0 loads back as -0.0 (0.0 + -0.0 is 0.0).
  void load(World& w, const json& l, const std::string& at) {
    const Vec3 force = vec3(l["force"]);
    for (int32_t i : particles_of(w, l, at)) {
      const Vec3 sum = w.loads()[i].isZero() ? force : Vec3(w.loads()[i] + force);
      guard(at + "/force", [&] {
        w.set_loads(i, std::span<const double>(sum.data(), 3));
        return 0;
      });
    }
  }

  void pins(World& w, const json& p, const std::string& at) {
    const std::vector<int32_t> particles = particles_of(w, p, at);
    for (size_t i = 0; i < particles.size(); ++i) {
      PinDesc d;
      d.particle = particles[i];
      d.target = w.positions()[particles[i]];
      read_rows(kPinRows, p, d);
      d.support = named_enum(p, "support", kPinSupportNames, d.support);
      if (p.contains("axis")) d.axis = vec3(p["axis"]);
      if (p.contains("points"))
        for (const json& c : p["points"]) d.curve.push_back(vec3(c));
      d.closed = p.contains("closed") && p["closed"].get<bool>();
      if (p.contains("vertices"))
        for (const json& c : p["vertices"]) d.curve.push_back(vec3(c));
      if (p.contains("triangles"))
        for (const json& t : p["triangles"])
          d.triangles.push_back({t[0].get<int32_t>(), t[1].get<int32_t>(), t[2].get<int32_t>()});
      d.group = group(p, "group", at);
      const Id id = guard(at, [&] { return w.create_pin(d); });
      if (p.contains("name")) {
        const std::string base = p["name"].get<std::string>();
        name_once(pins_, meta_.pin_names, particles.size() == 1 ? json(base) : json(base + "." + std::to_string(i)), id,
                  at, "pin");
      }
    }
  }

  void action(const json& a, const std::string& at) {
    Action act;
    const std::string type = a["type"].get<std::string>();
    size_t width = 3;
    if (type == "rest_scale") {
      act.type = Action::Type::rest_scale;
      act.target = named(bodies_, a, "body", at);
    } else if (type == "pin_target") {
      act.type = Action::Type::pin_target;
      act.target = named(pins_, a, "pin", at);
    } else if (type == "collider_pose") {
      act.type = Action::Type::collider_pose;
      act.target = named(colliders_, a, "collider", at);
    } else {
      act.type = Action::Type::gravity;
    }
    int64_t last = -1;
    for (size_t i = 0; i < a["keys"].size(); ++i) {
      const json& key = a["keys"][i];
      const std::string where = at + "/keys/" + std::to_string(i);
      const int64_t frame = key["frame"].get<int64_t>();
      if (frame <= last) fail(where + "/frame", "key frames must increase");
      last = frame;
      if (!key.contains("value")) fail(where, "needs a \"value\"");
      std::vector<double> value = key["value"].get<std::vector<double>>();
      // A collider's keys are all positions (3 numbers) or all poses (7: position and rotation).
      if (act.type == Action::Type::collider_pose && i == 0 && value.size() == 7) width = 7;
      if (value.size() != width)
        fail(where + "/value", "needs " + std::to_string(width) + " numbers" +
                                   (act.type != Action::Type::collider_pose ? ""
                                    : i == 0                                ? " (or 7: position and rotation)"
                                             : " like the action's first key (3: position; 7: position and rotation)"));
      if (width == 7) quat(json(std::vector<double>(value.begin() + 3, value.end())), where + "/value");
      if (act.type == Action::Type::rest_scale)
        for (double s : value)
          if (s < 0.0) fail(where + "/value", "rest scales must be >= 0");
      act.frames.push_back(frame);
      act.values.push_back(std::move(value));
    }
    meta_.actions.push_back(std::move(act));
  }

  void field(World& w, const json& f, const std::string& at) {
    const std::string type = f["type"].get<std::string>();
    FieldDesc d;
    if (f.contains("body")) d.body = static_cast<int32_t>(named(bodies_, f, "body", at).index);
    for (int k = 0; k < kFieldKindCount; ++k)  // the schema has checked the type is one of them
      if (type == kFieldKindNames[k]) d.kind = static_cast<FieldKind>(k);
    visit_field(d, [&](auto& desc, const auto& rows) { read_rows(rows, f, desc); });
    const Id id = guard(at, [&] { return w.create_field(d); });
    if (f.contains("name")) name_once(fields_, meta_.field_names, f["name"], id, at, "field");
  }

  const json& doc_;
  const LoadOptions& options_;
  SceneMeta& meta_;
  std::map<std::string, Id> groups_, bodies_, pins_, colliders_;
  std::map<std::string, Id> fields_;
  std::set<std::string> seen_groups_;
  std::set<size_t> frame_starts_used_;  // entries of /state/colliders matched to a collider
  std::map<uint32_t, std::map<std::string, std::vector<int32_t>>> sets_;
};

/// The names a scene gave (unique per kind: the loader refuses duplicates), reserved so that the
/// invented names of unnamed objects never take one of them.
std::set<std::string> given_names(const std::map<uint32_t, std::string>& names) {
  std::set<std::string> out;
  for (const auto& [slot, name] : names) out.insert(name);
  return out;
}

/// A name for every live object: its own, or "<what>_<slot>" made unique among all names in `used`
/// (which holds given_names(names)). Actions refer to objects by these names, so an object keeps its
/// own name: renaming it could hand its name, and its actions, to another object.
std::string name_for(const std::map<uint32_t, std::string>& names, uint32_t slot, const char* what,
                     std::set<std::string>& used) {
  const auto it = names.find(slot);
  if (it != names.end()) return it->second;
  std::string n = std::string(what) + "_" + std::to_string(slot);
  while (!used.insert(n).second) n += "_";
  return n;
}

}  // namespace

std::string_view scene_schema() {
  return kSceneSchema;
}

bool schema_pattern_matches(std::string_view pattern, std::string_view text) {
  if (pattern != kNamePattern)
    throw std::invalid_argument("the loader does not implement the pattern " + json(std::string(pattern)).dump());
  return matches_name_pattern(text);
}

std::unique_ptr<World> load_scene(std::string_view text, const std::string& base_dir, SceneMeta& out_meta) {
  LoadOptions options;
  options.base_dir = base_dir;
  return load_scene(text, options, out_meta);
}

std::unique_ptr<World> load_scene(std::string_view text, const LoadOptions& options, SceneMeta& out_meta) {
  const json doc = parse(text);
  // What the document is comes first: the schema alone would only say a `const` did not match.
  auto shown = [](const json& v) {
    const std::string s = v.dump(-1, ' ', true);  // ASCII, so cutting it keeps it valid UTF-8
    return s.size() > 64 ? s.substr(0, 60) + "..." : s;
  };
  if (doc.is_object() && doc.contains("format") && doc["format"] != "embra-scene")
    fail("/format", "is " + shown(doc["format"]) + ", not \"embra-scene\": this is not an embra scene");
  if (doc.is_object() && doc.contains("version") && doc["version"] != 1)
    fail("/version", "is " + shown(doc["version"]) + "; this library reads scene version 1");
  validate(doc, scene_schema_compiled(), "", "scene");
  if (doc.contains("tolerances")) {
    validate(doc["tolerances"], tolerances_schema_compiled(), "/tolerances", "tolerances");
    // What embra_world_set_tolerances refuses, a scene cannot hold either.
    for (const auto& [key, value] : doc["tolerances"].items())
      if (value.is_object() && value["target"].get<double>() > value["max"].get<double>())
        fail("/tolerances/" + key + "/target", "is above its max");
  }
  SceneMeta meta;
  auto world = Builder(doc, options, meta).build();
  out_meta = std::move(meta);
  return world;
}

std::string save_scene(const World& w, const SceneMeta& meta) {
  json doc = json::object();
  doc["format"] = "embra-scene";
  doc["version"] = 1;
  if (!meta.name.empty()) doc["name"] = meta.name;
  if (!meta.description.empty()) doc["description"] = meta.description;
  doc["frames"] = meta.frames;
  const Settings& s = w.settings();
  write_rows(kSolverRows, s, doc["solver"]);

  // Groups in creation order, so that equal orders resolve the same way when loaded.
  std::vector<uint32_t> slots;
  for (uint32_t i = 0; i < w.groups().size(); ++i)
    if (w.groups()[i].alive) slots.push_back(i);
  std::sort(slots.begin(), slots.end(),
            [&](uint32_t a, uint32_t b) { return w.groups()[a].serial < w.groups()[b].serial; });
  std::map<uint32_t, std::string> gname;
  std::set<std::string> used = given_names(meta.group_names);
  used.insert({"default", "contacts"});
  gname[w.default_group().index] = "default";
  gname[w.contact_group().index] = "contacts";
  json groups = json::array();
  for (uint32_t slot : slots) {
    if (!gname.count(slot)) gname[slot] = name_for(meta.group_names, slot, "group", used);
    json& g = groups.emplace_back(json{{"name", gname[slot]}});
    write_rows(kGroupRows, w.groups()[slot].desc, g);
  }
  doc["groups"] = groups;
  auto group_name = [&](Id id) { return gname.at(id.is_null() ? w.default_group().index : id.index); };

  json bodies = json::array();
  std::set<std::string> used_bodies = given_names(meta.body_names);
  for (uint32_t i = 0; i < w.body_count(); ++i) {
    const BodyInfo& b = w.body(Id{i, 1});
    const int32_t f = b.first_particle;
    json mesh;
    json vertices = json::array();
    for (const Vec3& p : b.rest_positions) vertices.push_back(vec_json(p));
    mesh["vertices"] = vertices;
    auto local = [&](const std::vector<int32_t>& ids, int n) {
      json out = json::array();
      for (size_t e = 0; e < ids.size(); e += n) {
        json el = json::array();
        for (int k = 0; k < n; ++k) el.push_back(ids[e + k] - f);
        out.push_back(el);
      }
      return out;
    };
    if (!b.edges.empty()) mesh["edges"] = local(b.edges, 2);
    if (!b.triangles.empty()) mesh["triangles"] = local(b.triangles, 3);
    if (!b.tets.empty()) mesh["tets"] = local(b.tets, 4);
    if (!b.uvs.empty()) {
      json uvs = json::array();
      for (size_t k = 0; k < b.uvs.size(); k += 2) uvs.push_back({b.uvs[k], b.uvs[k + 1]});
      mesh["uvs"] = uvs;
    }
    mesh["masses"] = b.masses;
    json generate = json::array();
    for (uint32_t k = 0; k < 4; ++k)
      if (b.generate & (1u << k)) generate.push_back(kGenerateNames[k]);
    bodies.push_back({{"name", name_for(meta.body_names, i, "body", used_bodies)},
                      {"mesh", mesh},
                      {"material", material_json(b.material)},
                      {"generate", generate},
                      {"stretch_group", group_name(b.stretch_group)},
                      {"shear_group", group_name(b.shear_group)},
                      {"bend_group", group_name(b.bend_group)},
                      {"volume_group", group_name(b.volume_group)},
                      {"rest_scale", {b.rest_scale, b.rest_scale_u, b.rest_scale_v}}});
  }
  doc["bodies"] = bodies;

  json panel_meshes = json::array();
  for (const PanelLayout& l : w.panel_layouts()) {
    json quads = json::array();
    for (size_t q = 0; q < l.quads.size(); q += 4)
      quads.push_back({l.quads[q], l.quads[q + 1], l.quads[q + 2], l.quads[q + 3]});
    panel_meshes.push_back({{"body", bodies[l.body.index]["name"]},
                            {"vertex_count", l.vertex_count},
                            {"quads", quads},
                            {"thickness", l.thickness},
                            {"corners", kPanelCornersNames[l.shared ? 1 : 0]},
                            {"precision", kPanelPrecisionNames[l.single ? 1 : 0]}});
  }
  if (!panel_meshes.empty()) doc["panel_meshes"] = panel_meshes;

  // Added constraints, per group and kind, in projection order; generated ones come from bodies.
  json constraints = json::array();
  for (uint32_t slot : slots) {
    const Group& g = w.groups()[slot];
    for (int k = 0; k < kKindCount; ++k) {
      const ConstraintArray& a = g.arrays[k];
      if (a.size() == a.generated) continue;
      const int n = arity(static_cast<Kind>(k));
      json particles = json::array(), rest = json::array(), compliance = json::array(), yield = json::array(),
           rupture = json::array();
      bool plastic = false;
      for (size_t i = a.generated; i < a.size(); ++i) {
        json ops = json::array();
        for (int c = 0; c < n; ++c) ops.push_back(a.ids[i * n + c]);
        particles.push_back(ops);
        rest.push_back(a.rest[i]);
        compliance.push_back(a.compliance[i]);
        yield.push_back(a.yield[i]);
        rupture.push_back(a.rupture[i]);
        plastic = plastic || a.yield[i] != 0.0 || a.rupture[i] != 0.0;
      }
      json batch = {{"kind", kind_name(static_cast<Kind>(k))},
                    {"group", gname[slot]},
                    {"particles", particles},
                    {"rest", rest},
                    {"compliance", compliance}};
      if (plastic) {  // written only when used, so a scene without them saves as before
        batch["yield"] = yield;
        batch["rupture"] = rupture;
      }
      constraints.push_back(batch);
    }
  }
  doc["constraints"] = constraints;

  json pins = json::array();
  std::set<std::string> used_pins = given_names(meta.pin_names);
  std::map<uint32_t, std::string> pin_name;
  // Hard pins in slot order, then each group's soft pins in the order the group projects them
  // (creation order, which a reused slot breaks): a loaded scene lists them in that order again.
  std::vector<uint32_t> pin_order;
  for (uint32_t i = 0; i < w.pins().size(); ++i)
    if (w.pins()[i].alive && w.pins()[i].kinematic()) pin_order.push_back(i);
  for (uint32_t slot : slots)
    for (int32_t i : w.groups()[slot].soft_pins) pin_order.push_back(static_cast<uint32_t>(i));
  for (uint32_t i : pin_order) {
    const Pin& p = w.pins()[i];
    pin_name[i] = name_for(meta.pin_names, i, "pin", used_pins);
    json j = {{"name", pin_name[i]}, {"particle", p.particle}};
    write_rows(kPinRows, PinDesc{p.particle, p.target, p.compliance, p.group}, j);
    if (!p.kinematic()) j["group"] = group_name(p.group);
    if (p.support == PinSupport::polyline) {
      j["support"] = kPinSupportNames[static_cast<int>(p.support)];
      json points = json::array();
      for (const Vec3& c : p.curve) points.push_back(vec_json(c));
      j["points"] = points;
      j["closed"] = p.closed;
    } else if (p.support == PinSupport::mesh) {
      j["support"] = kPinSupportNames[static_cast<int>(p.support)];
      json vertices = json::array(), triangles = json::array();
      for (const Vec3& c : p.curve) vertices.push_back(vec_json(c));
      for (const auto& t : p.triangles) triangles.push_back({t[0], t[1], t[2]});
      j["vertices"] = vertices;
      j["triangles"] = triangles;
    } else if (p.support != PinSupport::point) {
      j["support"] = kPinSupportNames[static_cast<int>(p.support)];
      j["axis"] = vec_json(p.axis);
    }
    pins.push_back(j);
  }
  doc["pins"] = pins;

  json loads = json::array();
  for (int32_t i = 0; i < w.particle_count(); ++i)
    if (!w.loads()[i].isZero()) loads.push_back({{"particle", i}, {"force", vec_json(w.loads()[i])}});
  if (!loads.empty()) doc["loads"] = loads;
  json area_loads = json::array();
  for (const AreaLoad& l : w.area_loads())
    area_loads.push_back({{"particles", {l.particles[0], l.particles[1], l.particles[2]}},
                          {"mode", kAreaLoadModeNames[static_cast<int>(l.mode)]},
                          {"pressure", l.pressure},
                          {"direction", vec_json(l.direction)}});
  if (!area_loads.empty()) doc["area_loads"] = area_loads;
  json line_loads = json::array();
  for (const LineLoad& l : w.line_loads())
    line_loads.push_back({{"particles", {l.particles[0], l.particles[1]}}, {"load", vec_json(l.load)}});
  if (!line_loads.empty()) doc["line_loads"] = line_loads;

  // Each group's shape matches in the order it projects them, groups in creation order.
  json shape_matches = json::array();
  for (uint32_t slot : slots)
    for (const ShapeMatch& m : w.groups()[slot].shapes) {
      json rest = json::array();
      for (const Vec3& r : m.rest) rest.push_back(vec_json(r));
      shape_matches.push_back(
          {{"group", gname[slot]}, {"particles", m.particles}, {"rest", rest}, {"compliance", m.compliance}});
    }
  if (!shape_matches.empty()) doc["shape_matches"] = shape_matches;

  json colliders = json::array();
  std::set<std::string> used_colliders = given_names(meta.collider_names);
  std::map<uint32_t, std::string> collider_name;
  for (uint32_t i = 0; i < w.colliders().size(); ++i) {
    const Collider& c = w.colliders()[i];
    if (!c.alive) continue;
    const Eigen::Quaterniond& q = c.desc.rotation;
    collider_name[i] = name_for(meta.collider_names, i, "collider", used_colliders);
    json& out = colliders.emplace_back(json{{"name", collider_name[i]},
                                            {"shape", kColliderShapeNames[static_cast<int>(c.desc.shape)]},
                                            {"rotation", {q.w(), q.x(), q.y(), q.z()}}});
    write_rows(kColliderRows, c.desc, out);
    if (c.desc.shape == ColliderShape::convex || c.desc.shape == ColliderShape::mesh) {
      json v = json::array();
      for (size_t k = 0; k + 2 < c.desc.vertices.size(); k += 3)
        v.push_back({c.desc.vertices[k], c.desc.vertices[k + 1], c.desc.vertices[k + 2]});
      out["vertices"] = v;
    }
    if (c.desc.shape == ColliderShape::mesh) {
      json t = json::array();
      for (size_t k = 0; k + 2 < c.desc.triangles.size(); k += 3)
        t.push_back({c.desc.triangles[k], c.desc.triangles[k + 1], c.desc.triangles[k + 2]});
      out["triangles"] = t;
    }
  }
  doc["colliders"] = colliders;

  json fields = json::array();
  for (uint32_t i = 0; i < w.fields().size(); ++i) {
    const Field& f = w.fields()[i];
    if (!f.alive) continue;
    const FieldDesc& d = f.desc;
    json j = {{"type", kFieldKindNames[static_cast<int>(d.kind)]}};
    visit_field(d, [&](const auto& desc, const auto& rows) { write_rows(rows, desc, j); });
    if (d.body >= 0) j["body"] = bodies[d.body]["name"];
    const auto named_field = meta.field_names.find(i);
    if (named_field != meta.field_names.end()) j["name"] = named_field->second;
    fields.push_back(j);
  }
  if (!fields.empty()) doc["fields"] = fields;

  json actions = json::array();
  for (const Action& a : meta.actions) {
    json j;
    json keys = json::array();
    for (size_t k = 0; k < a.frames.size(); ++k) keys.push_back({{"frame", a.frames[k]}, {"value", a.values[k]}});
    switch (a.type) {
      case Action::Type::rest_scale:
        j = {{"type", "rest_scale"}, {"body", bodies[a.target.index]["name"]}};
        break;
      case Action::Type::pin_target:
        j = {{"type", "pin_target"}, {"pin", pin_name.at(a.target.index)}};
        break;
      case Action::Type::collider_pose:
        j = {{"type", "collider_pose"}, {"collider", collider_name.at(a.target.index)}};
        break;
      case Action::Type::gravity:
        j = {{"type", "gravity"}};
        break;
    }
    j["keys"] = keys;
    actions.push_back(j);
  }
  doc["actions"] = actions;
  if (!meta.tolerances.empty()) doc["tolerances"] = json::parse(meta.tolerances);

  json positions = json::array(), velocities = json::array();
  for (const Vec3& p : w.positions()) positions.push_back(vec_json(p));
  for (const Vec3& v : w.velocities()) velocities.push_back(vec_json(v));
  doc["state"] = {
      {"frame", w.report().frame}, {"time", w.report().time}, {"positions", positions}, {"velocities", velocities}};
  json moved = json::array();  // colliders moved since the last step: where the next step sweeps them from
  for (uint32_t i = 0; i < w.colliders().size(); ++i) {
    const Collider& c = w.colliders()[i];
    if (!c.alive || (c.frame_position == c.desc.position && c.frame_rotation.coeffs() == c.desc.rotation.coeffs()))
      continue;
    const Eigen::Quaterniond& q = c.frame_rotation;
    moved.push_back({{"collider", collider_name.at(i)},
                     {"position", vec_json(c.frame_position)},
                     {"rotation", {q.w(), q.x(), q.y(), q.z()}}});
  }
  if (!moved.empty()) doc["state"]["colliders"] = moved;
  // The forces the readers read (a world stepped at least once): groups in creation order, pins in
  // the order listed, contacts in the order found (the order the reaction sums them in).
  const StaticsState st = w.statics_state();
  const auto in_range = [](double v) { return std::abs(v) <= limits::kMaxAbsValue; };
  bool savable = true;  // a multiplier beyond +-1e300 (no scene at rest holds one) keeps it out
  for (const auto& m : st.constraints)
    for (double v : m.lambda) savable = savable && in_range(v);
  for (const auto& t : st.tethers)
    for (double v : t.lambda) savable = savable && in_range(v);
  for (const auto& p : st.pins)
    for (int k = 0; k < 3; ++k) savable = savable && in_range(p.lambda[k]);
  for (const Contact& ct : st.contacts)
    for (int k = 0; k < 3; ++k) savable = savable && in_range(ct.force_h2[k]);
  for (const FaceContact& fc : st.face_contacts)
    for (int k = 0; k < 3; ++k) savable = savable && in_range(fc.force_h2[k]);
  if (!st.empty() && savable) {
    json forces = json::object();
    json list = json::array(), tethers = json::array();
    for (uint32_t slot : slots) {
      for (const auto& m : st.constraints)
        if (m.group.index == slot)
          list.push_back({{"group", gname.at(slot)}, {"kind", kind_name(m.kind)}, {"multipliers", m.lambda}});
      for (const auto& t : st.tethers)
        if (t.group.index == slot) tethers.push_back({{"group", gname.at(slot)}, {"multipliers", t.lambda}});
    }
    if (!list.empty()) forces["constraints"] = list;
    if (!tethers.empty()) forces["tethers"] = tethers;
    std::map<uint32_t, Vec3> pin_lambda;
    for (const auto& p : st.pins) pin_lambda[p.pin.index] = p.lambda;
    json pin_list = json::array();
    for (uint32_t i : pin_order)
      if (pin_lambda.count(i)) pin_list.push_back({{"pin", pin_name.at(i)}, {"multiplier", vec_json(pin_lambda[i])}});
    if (!pin_list.empty()) forces["pins"] = pin_list;
    json contacts = json::array(), face_contacts = json::array();
    for (const Contact& ct : st.contacts)
      contacts.push_back({{"particle", ct.particle},
                          {"collider", collider_name.at(static_cast<uint32_t>(ct.collider))},
                          {"force_h2", vec_json(ct.force_h2)}});
    for (const FaceContact& fc : st.face_contacts)
      face_contacts.push_back({{"particles", {fc.ids[0], fc.ids[1], fc.ids[2]}},
                               {"collider", collider_name.at(static_cast<uint32_t>(fc.collider))},
                               {"force_h2", vec_json(fc.force_h2)}});
    if (!contacts.empty()) forces["contacts"] = contacts;
    if (!face_contacts.empty()) forces["face_contacts"] = face_contacts;
    doc["state"]["forces"] = forces;
  }
  return doc.dump(1) + "\n";
}

Tolerances parse_tolerances(const std::string& text) {
  Tolerances t;
  if (text.empty()) return t;
  const json doc = json::parse(text);
  read_rows(kTolerancesRows, doc, t);
  return t;
}

std::string tolerances_json(const Tolerances& t) {
  json doc = {{"format", "embra-tolerances"}, {"version", 1}};
  write_rows(kTolerancesRows, t, doc);
  return doc.dump();
}

void apply_actions(World& w, const SceneMeta& meta, int64_t frame) {
  for (const Action& a : meta.actions) {
    // Linear between the keys around `frame`, held outside them.
    size_t hi = 0;
    while (hi < a.frames.size() && a.frames[hi] < frame) ++hi;
    std::vector<double> v;
    if (hi == 0)
      v = a.values.front();
    else if (hi == a.frames.size())
      v = a.values.back();
    else {
      const double t =
          static_cast<double>(frame - a.frames[hi - 1]) / static_cast<double>(a.frames[hi] - a.frames[hi - 1]);
      std::vector<double> from = a.values[hi - 1];
      const std::vector<double>& to = a.values[hi];
      if (from.size() == 7) {
        // q and -q are one rotation: turn along the shorter arc (from the earlier key's sign flipped
        // when the keys point apart), so the blend never passes through the zero quaternion.
        double dot = 0.0;
        for (size_t k = 3; k < 7; ++k) dot += from[k] * to[k];
        if (dot < 0.0)
          for (size_t k = 3; k < 7; ++k) from[k] = -from[k];
      }
      v.resize(to.size());
      for (size_t k = 0; k < v.size(); ++k) v[k] = (1.0 - t) * from[k] + t * to[k];
    }
    switch (a.type) {
      case Action::Type::rest_scale:
        w.set_rest_scale(a.target, v[0], v[1], v[2]);
        break;
      case Action::Type::pin_target:
        w.set_pin_target(a.target, Vec3(v[0], v[1], v[2]));
        break;
      case Action::Type::collider_pose: {
        const Collider& c = w.collider(a.target);
        const Eigen::Quaterniond q =
            v.size() == 7 ? unit_rotation(Eigen::Quaterniond(v[3], v[4], v[5], v[6])) : c.desc.rotation;
        w.set_collider_transform(a.target, Vec3(v[0], v[1], v[2]), q);
        break;
      }
      case Action::Type::gravity:
        w.set_gravity(Vec3(v[0], v[1], v[2]));
        break;
    }
  }
}

}  // namespace embra::io
