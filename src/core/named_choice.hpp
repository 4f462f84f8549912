#pragma once
// A configuration choice from its name: the enum value a table pairs with the name, or a one-line
// error naming the key and the allowed names (core/config.cpp checks the names first; this is what
// turns them into the enums the code compares).
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "core/error.hpp"

namespace sphdisk {

template <class E>
using NamedChoice = std::pair<std::string_view, E>;

template <class E>
E choice_from_name(std::string_view key, std::string_view name, std::span<const NamedChoice<E>> choices) {
  std::string allowed;
  for (const auto& [n, e] : choices) {
    if (n == name) return e;
    allowed += (allowed.empty() ? "" : ", ") + std::string(n);
  }
  throw UserError("unknown " + std::string(key) + " '" + std::string(name) + "'; use one of " + allowed);
}

}  // namespace sphdisk
