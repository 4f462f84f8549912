#pragma once
// Particles packed into byte buffers for the domain's messages (migration, halo, regrouping by ID):
// a particle count, then each selected field of the table in order.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <type_traits>
#include <vector>

#include "core/particles.hpp"

namespace sphdisk {

// The fields to move: empty = every field of the table.
using FieldNames = std::vector<std::string_view>;

namespace packing {

inline bool selected(const FieldNames& fields, std::string_view name) {
  return fields.empty() || std::find(fields.begin(), fields.end(), name) != fields.end();
}

// Buffer layout: particle count, then each selected field in table order.
template <int D>
std::vector<std::byte> pack(const Particles<D>& p, const std::vector<std::uint32_t>& idx, const FieldNames& fields) {
  std::vector<std::byte> buf(sizeof(std::uint64_t));
  const std::uint64_t n = idx.size();
  std::memcpy(buf.data(), &n, sizeof n);
  p.for_each_field([&](const FieldInfo& info, const auto& v) {
    using T = typename std::remove_reference_t<decltype(v)>::value_type;
    static_assert(std::is_trivially_copyable_v<T>);
    if (!selected(fields, info.name)) return;
    const std::size_t at = buf.size();
    buf.resize(at + idx.size() * sizeof(T));
    for (std::size_t k = 0; k < idx.size(); ++k) std::memcpy(buf.data() + at + k * sizeof(T), &v[idx[k]], sizeof(T));
  });
  return buf;
}

inline std::uint64_t packed_count(const std::vector<std::byte>& buf) {
  std::uint64_t n = 0;
  if (buf.size() >= sizeof n) std::memcpy(&n, buf.data(), sizeof n);
  return n;
}

// Writes the buffer's particles into p at [first, first + count) (p already large enough).
template <int D>
void unpack(Particles<D>& p, std::size_t first, const std::vector<std::byte>& buf, const FieldNames& fields) {
  const std::uint64_t n = packed_count(buf);
  std::size_t at = sizeof(std::uint64_t);
  p.for_each_field([&](const FieldInfo& info, auto& v) {
    using T = typename std::remove_reference_t<decltype(v)>::value_type;
    if (!selected(fields, info.name)) return;
    if (n > 0) std::memcpy(static_cast<void*>(&v[first]), buf.data() + at, n * sizeof(T));
    at += n * sizeof(T);
  });
}

// Appends every buffer's particles to p.
template <int D>
void unpack_all(Particles<D>& p, const std::vector<std::vector<std::byte>>& bufs, const FieldNames& fields = {}) {
  std::size_t n = p.size();
  for (const auto& buf : bufs) n += packed_count(buf);
  std::size_t first = p.size();
  p.resize(n);
  for (const auto& buf : bufs) {
    unpack(p, first, buf, fields);
    first += packed_count(buf);
  }
}

}  // namespace packing
}  // namespace sphdisk
