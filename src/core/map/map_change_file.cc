#include "pf_localization/core/map/map_change_file.h"

#include <cstdint>

namespace pf {
namespace {

constexpr char kMagic[] = "pf_localization map changes\n";
constexpr std::size_t kMagicSize = sizeof kMagic - 1;

std::uint64_t fnv1a(const std::string& bytes) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (const char c : bytes) {
    h ^= static_cast<std::uint8_t>(c);
    h *= 0x100000001b3ull;
  }
  return h;
}

// Fixed-size integers, the lowest byte first.
void putFixed(std::string* out, std::uint64_t v, int bytes) {
  for (int k = 0; k < bytes; ++k) out->push_back(static_cast<char>(v >> (8 * k) & 0xff));
}

std::uint64_t fixedAt(const std::string& bytes, std::size_t at, int size) {
  std::uint64_t v = 0;
  for (int k = 0; k < size; ++k) {
    v |= static_cast<std::uint64_t>(static_cast<std::uint8_t>(bytes[at + k])) << (8 * k);
  }
  return v;
}

}  // namespace

// kMagic, the version (4 bytes), the signature's length (4) and the
// signature, the state's length (8), the state, its checksum (8).
std::string mapChangesFile(const MapChangeLayer& layer, const std::string& map_signature) {
  const std::string state = layer.encode();
  std::string out(kMagic, kMagicSize);
  putFixed(&out, kMapChangesFileVersion, 4);
  putFixed(&out, map_signature.size(), 4);
  out += map_signature;
  putFixed(&out, state.size(), 8);
  out += state;
  putFixed(&out, fnv1a(state), 8);
  return out;
}

MapChangesFileContents readMapChangesFile(const std::string& bytes) {
  MapChangesFileContents out;
  if (bytes.compare(0, kMagicSize, kMagic, kMagicSize) != 0) {
    out.error =
        bytes.size() < kMagicSize && std::string(kMagic).compare(0, bytes.size(), bytes) == 0
            ? "cut short in its header"
            : "not a map changes file";
    return out;
  }
  std::size_t at = kMagicSize;
  if (bytes.size() < at + 8) {
    out.error = "cut short in its header";
    return out;
  }
  const std::uint64_t version = fixedAt(bytes, at, 4), signature = fixedAt(bytes, at + 4, 4);
  at += 8;
  if (version != kMapChangesFileVersion) {
    out.error = "format version " + std::to_string(version) + ", this build reads version " +
                std::to_string(kMapChangesFileVersion);
    return out;
  }
  if (bytes.size() - at < signature + 8) {
    out.error = "cut short in its header";
    return out;
  }
  out.map_signature = bytes.substr(at, signature);
  at += signature;
  const std::uint64_t state = fixedAt(bytes, at, 8);
  at += 8;
  if (bytes.size() - at < 8 || bytes.size() - at - 8 < state) {
    out.error = "cut short: " + std::to_string(bytes.size() - at) +
                " bytes of state and checksum, " + std::to_string(state) + " + 8 expected";
    return out;
  }
  out.state = bytes.substr(at, state);
  at += state;
  if (bytes.size() - at != 8 || fixedAt(bytes, at, 8) != fnv1a(out.state)) {
    out.error = bytes.size() - at != 8 ? "corrupt: bytes after its checksum"
                                       : "corrupt: the checksum does not match its state";
    out.state.clear();
  }
  return out;
}

}  // namespace pf
