#pragma once
// Fields of a benchmark JSON file read with their type checked, for compare's readers
// (bench_compare.cpp: the benchmarks; compare_context.cpp: the context). A field that is
// absent, or null (what Google Benchmark's NaN becomes, bench_compare.cpp), is "not
// given"; one of another type, or a number out of its range, is bad input: InputError
// "PATH: FIELD: expected WHAT, got WHAT-IT-IS". Nothing here indexes a missing key or
// converts a value of the wrong type (nlohmann's operator[] on a const object's missing
// key is undefined behaviour; get<T> of the wrong type throws a type_error, which
// pathbench would report as an internal failure).
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <optional>
#include <string>

#include "pathbench/common/errors.h"

namespace pb::analysis::fields {

using Json = nlohmann::json;

// What a value is, for a message: "number 5", "string \"abc\"", "array", "object", "null", "true".
inline std::string what_is(const Json& v) {
  if (v.is_string()) {
    const std::string& s = v.get_ref<const std::string&>();
    return s.size() <= 40 ? fmt::format("string \"{}\"", s) : fmt::format("string of {} bytes", s.size());
  }
  if (v.is_number()) {
    const std::string d = v.dump();
    return "number " + (d.size() <= 40 ? d : d.substr(0, 40) + "...");
  }
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_array()) return "array";
  if (v.is_object()) return "object";
  return "null";
}

[[noreturn]] inline void wrong(const std::string& path, const std::string& field, const std::string& expected,
                               const Json& got) {
  throw InputError(fmt::format("{}: {}: expected {}, got {}", path, field, expected, what_is(got)));
}

// The member `key` of object `obj`, or nullptr when it is absent or null.
inline const Json* member(const Json& obj, const char* key) {
  const auto it = obj.find(key);
  return it == obj.end() || it->is_null() ? nullptr : &*it;
}

// A field reader over one object of one file: `path` names the file, `where` the object
// ("context", "benchmarks[3]") in messages.
class Reader {
 public:
  Reader(const std::string& path, const Json& obj, std::string where) : path_(path), obj_(obj), where_(std::move(where)) {}

  std::string field(const char* key) const { return where_.empty() ? key : where_ + "." + key; }
  const std::string& path() const { return path_; }
  const Json& json() const { return obj_; }
  bool has(const char* key) const { return member(obj_, key) != nullptr; }

  const Json* object(const char* key) const { return typed(key, &Json::is_object, "an object"); }
  const Json* array(const char* key) const { return typed(key, &Json::is_array, "an array"); }
  std::optional<std::string> string(const char* key) const {
    const Json* v = typed(key, &Json::is_string, "a string");
    return v ? std::optional(v->get<std::string>()) : std::nullopt;
  }
  std::string string_or(const char* key, std::string fallback) const { return string(key).value_or(std::move(fallback)); }
  std::optional<bool> boolean(const char* key) const {
    const Json* v = typed(key, &Json::is_boolean, "true or false");
    return v ? std::optional(v->get<bool>()) : std::nullopt;
  }
  // A finite number in [lo, hi] (integer: a whole number).
  std::optional<double> number(const char* key, double lo, double hi, bool integer = false) const {
    const Json* v = member(obj_, key);
    if (!v) return std::nullopt;
    return number_value(*v, field(key), lo, hi, integer);
  }
  std::optional<double> number_value(const Json& v, const std::string& name, double lo, double hi,
                                     bool integer = false) const {
    const std::string expected = fmt::format("{} in [{}, {}]", integer ? "a whole number" : "a number", lo, hi);
    if (!v.is_number()) wrong(path_, name, expected, v);
    const double x = v.get<double>();  // exact for every integer the range checks below admit
    if (!(std::isfinite(x) && x >= lo && x <= hi) || (integer && x != std::floor(x))) wrong(path_, name, expected, v);
    return x;
  }
  Reader sub(const Json& v, const std::string& name) const { return Reader(path_, v, name); }

 private:
  const Json* typed(const char* key, bool (Json::*is)() const noexcept, const char* expected) const {
    const Json* v = member(obj_, key);
    if (v && !(v->*is)()) wrong(path_, field(key), expected, *v);
    return v;
  }
  const std::string& path_;
  const Json& obj_;
  std::string where_;
};

}  // namespace pb::analysis::fields
