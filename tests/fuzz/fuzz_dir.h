#pragma once
// A scratch folder for one fuzz target's process (under /dev/shm when it exists, so that the
// files each input is written to never reach a disk), removed at exit.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace boxd::fuzz {

inline const std::filesystem::path& ScratchDir() {
    static const struct Dir {
        std::filesystem::path path;
        Dir() {
            const std::filesystem::path base =
                std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
            path = base / ("boxd-fuzz-" + std::to_string(::getpid()));
            std::filesystem::create_directories(path);
        }
        ~Dir() {
            std::error_code ec;
            std::filesystem::remove_all(path, ec);
        }
    } dir;
    return dir.path;
}

// Writes `bytes` to `path`, replacing it.
inline void WriteFile(const std::filesystem::path& path, std::string_view bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc)
        .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace boxd::fuzz
