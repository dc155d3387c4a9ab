#pragma once
// Input and output: the `software` block of a measurement result (an addition to SPEC section
// 5): the identification of the program that measured it — the legally relevant software of
// WELMEC guide 7.2 — its version, the commit it was built from and the SHA-256 of its binary.

#include <nlohmann/json_fwd.hpp>
#include <string>

namespace boxd {

struct SoftwareIdentity {
    std::string version;  // "0.1.0"
    std::string commit;   // "b3d8619a2f4c" ("-dirty" for a tree with changes)
    std::string sha256;   // of the running executable, 64 hex digits

    bool operator==(const SoftwareIdentity&) const = default;
};

// {"version", "commit", "sha256"}.
nlohmann::json ToJson(const SoftwareIdentity& software);

}  // namespace boxd
