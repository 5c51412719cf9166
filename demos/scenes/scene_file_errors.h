#pragma once
// The error reporting of scene files, shared by scene_file_errors.cpp and scene_file_read.cpp:
// a private header of cps_scenes, not its API (scene_file.h is). Every error is a SceneFileError
// whose message names the file, the JSON pointer of the value (or the line and column for a
// syntax error), the value and what is allowed.

#include <nlohmann/json.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace cps::scenes::detail {

/// A value as it appears in a message: its JSON text, cut at 60 characters. No errors.
std::string shown(const nlohmann::json& v);

/// Throws SceneFileError "ORIGIN: POINTER: WHY" ("(top level)" for an empty pointer).
[[noreturn]] void fail(const std::string& origin, const std::string& pointer,
                       const std::string& why);

/// The words separated by ", " ("" for none), for the list of what is allowed. No errors.
std::string joined(const std::vector<std::string>& words);

/// Parses the JSON text of a scene file, comments allowed (the first of scene_file.h's passes).
/// Throws SceneFileError naming `origin`, with LINE:COLUMN where known and the pointer of the
/// open objects and arrays, for a syntax error, nesting deeper than kMaxSceneFileDepth, a key
/// twice in one object, a number out of the range of a double, or a NUL byte.
nlohmann::json parse_json_text(std::string_view text, const std::string& origin);

/// Checks a parsed scene file against the schema (the second pass, valijson). Throws
/// SceneFileError for its most precise error: an unknown key (naming the nearest known one), a
/// missing required key, or the value and what its schema allows, at its pointer.
void validate_against_schema(const std::string& origin, const nlohmann::json& doc);

}  // namespace cps::scenes::detail
