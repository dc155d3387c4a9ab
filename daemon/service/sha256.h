#pragma once
// SHA-256 (FIPS 180-4, through OpenSSL's libcrypto) as lowercase hex: the binary's
// identification and the stored records' hash chain.

#include <filesystem>
#include <string>
#include <string_view>

#include "pipeline/core/result.h"

namespace boxd {

// Returns the 64 hex digits of SHA-256 over `data`.
std::string Sha256Hex(std::string_view data);

// Returns the 64 hex digits of SHA-256 over the file at `path`, or IO_ERROR naming it.
Result<std::string> Sha256OfFile(const std::filesystem::path& path);

}  // namespace boxd
