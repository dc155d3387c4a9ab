#include "pipeline/io/software_block.h"

#include <nlohmann/json.hpp>

namespace boxd {

nlohmann::json ToJson(const SoftwareIdentity& s) {
    return {{"version", s.version}, {"commit", s.commit}, {"sha256", s.sha256}};
}

}  // namespace boxd
