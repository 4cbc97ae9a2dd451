#pragma once
namespace morphoflow {
inline constexpr const char* kVersion = "0.1.0";
}
