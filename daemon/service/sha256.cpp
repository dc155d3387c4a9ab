#include "daemon/service/sha256.h"

#include <openssl/evp.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <memory>
#include <vector>

namespace boxd {

namespace {

struct DigestDeleter {
    void operator()(EVP_MD_CTX* ctx) const { EVP_MD_CTX_free(ctx); }
};
using Digest = std::unique_ptr<EVP_MD_CTX, DigestDeleter>;

Digest NewDigest() {
    Digest ctx(EVP_MD_CTX_new());
    if (ctx) EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr);
    return ctx;
}

std::string Hex(const Digest& ctx) {
    std::array<unsigned char, EVP_MAX_MD_SIZE> md{};
    unsigned int n = 0;
    EVP_DigestFinal_ex(ctx.get(), md.data(), &n);
    std::string out;
    out.reserve(2 * n);
    char byte[3];
    for (unsigned int i = 0; i < n; ++i) {
        std::snprintf(byte, sizeof(byte), "%02x", md[i]);
        out += byte;
    }
    return out;
}

}  // namespace

std::string Sha256Hex(std::string_view data) {
    Digest ctx = NewDigest();
    EVP_DigestUpdate(ctx.get(), data.data(), data.size());
    return Hex(ctx);
}

Result<std::string> Sha256OfFile(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return Error{ErrorCode::kIoError, "cannot read " + path.string()};
    Digest ctx = NewDigest();
    std::vector<char> buffer(1 << 16);
    while (in) {
        in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
        if (in.gcount() > 0) {
            EVP_DigestUpdate(ctx.get(), buffer.data(), static_cast<std::size_t>(in.gcount()));
        }
    }
    if (in.bad()) return Error{ErrorCode::kIoError, "cannot read " + path.string()};
    return Hex(ctx);
}

}  // namespace boxd
