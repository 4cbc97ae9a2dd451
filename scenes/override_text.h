// An override (--set's "key=value") made from a key and a value given apart,
// as the Python module's set= dict gives them: the key must be a dotted path
// of bare names, and a string value is written as a TOML string, so that no
// '=', quote or newline inside either can set another key.
#pragma once

#include <string>
#include <string_view>

namespace morphoflow {

// Names of letters, digits, '_' and '-' joined by single dots ("fluid.reynolds", "sources.0.radius").
bool isDottedKey(std::string_view key);
// s as a TOML basic string: quoted, with '"', '\' and control characters escaped.
std::string tomlString(std::string_view s);

}  // namespace morphoflow
