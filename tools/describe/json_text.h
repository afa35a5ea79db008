// JSON values as text, the one way every JSON the tools write (robotalk-describe,
// the robotalk CLI's --json outputs, robotalk-web's messages) is produced.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace robotalk {

/// `value` as one line of JSON text. Numbers are written in the shortest form
/// that reads back exactly, non-finite ones as null; bytes of a string that
/// are not UTF-8 (names from files or from the wire) become U+FFFD instead of
/// throwing. ordered_json keeps its keys in the order they were inserted.
std::string JsonText(const nlohmann::ordered_json& value);
std::string JsonText(const nlohmann::json& value);

}  // namespace robotalk
