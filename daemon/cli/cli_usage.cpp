// What the command line says before any subcommand runs: the usage of a bare `boxd`, the version,
// and an unknown command or option named as such, with the nearest valid one. CLI11 alone would
// answer `boxd mesure` with "A subcommand is required" and `boxd measure --bogus` with the first
// missing required option.
#include <spdlog/fmt/ranges.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "daemon/cli/build_info.h"
#include "daemon/cli/cli.h"

namespace boxd::cli {

namespace {

// The edit distance (insertions, deletions, substitutions) between `a` and `b`.
std::size_t EditDistance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
            diagonal = above;
        }
    }
    return row[b.size()];
}

// Returns " (did you mean X?)" for the name in `names` nearest `word`, when it is near enough to
// be a slip (at most a third of its letters, at least two, wrong), else "".
std::string Suggestion(const std::string& word, const std::vector<std::string>& names) {
    std::string best;
    std::size_t best_distance = std::max<std::size_t>(2, word.size() / 3) + 1;
    for (const std::string& name : names) {
        const std::size_t d = EditDistance(word, name);
        if (d < best_distance) {
            best = name;
            best_distance = d;
        }
    }
    return best.empty() ? "" : " (did you mean " + best + "?)";
}

std::vector<std::string> SubcommandNames(const CLI::App& app) {
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
        names.push_back(sub->get_name());
    }
    return names;
}

// The long option names of `app` ("--session"), the help flag's among them.
std::vector<std::string> LongOptionNames(const CLI::App& app) {
    std::vector<std::string> names;
    for (const CLI::Option* opt : app.get_options()) {
        for (const std::string& name : opt->get_lnames()) names.push_back("--" + name);
    }
    return names;
}

// The error for the long options in argv[first..] that `sub` does not have, or nothing.
std::optional<Error> UnknownOption(const CLI::App& sub, const std::string& command, int first,
                                   int argc, char** argv) {
    const std::vector<std::string> names = LongOptionNames(sub);
    for (int i = first; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--") break;  // what follows is values only
        if (arg.rfind("--", 0) != 0) continue;
        const std::string name = arg.substr(0, arg.find('='));
        if (std::find(names.begin(), names.end(), name) != names.end()) continue;
        return Error{ErrorCode::kInvalidInput, command + ": unknown option " + name +
                                                   Suggestion(name, names) + " (see " + command +
                                                   " --help)"};
    }
    return std::nullopt;
}

}  // namespace

std::string VersionText() {
    return std::string("boxd ") + BuildVersion() + " (commit " + BuildCommit() + ", " +
           BuildType() + " build)";
}

std::optional<Error> CheckArguments(const CLI::App& app, int argc, char** argv) {
    if (argc < 2) return std::nullopt;
    const std::string first = argv[1];
    if (first.rfind("-", 0) == 0) {
        const std::vector<std::string> names = LongOptionNames(app);
        if (first == "-h" || std::find(names.begin(), names.end(), first) != names.end()) {
            return std::nullopt;
        }
        return Error{ErrorCode::kInvalidInput,
                     "unknown option " + first + Suggestion(first, names) + " (see boxd --help)"};
    }
    const std::vector<std::string> commands = SubcommandNames(app);
    if (std::find(commands.begin(), commands.end(), first) == commands.end()) {
        return Error{ErrorCode::kInvalidInput,
                     "unknown command '" + first + "'" + Suggestion(first, commands) +
                         "; the commands are " + fmt::format("{}", fmt::join(commands, ", "))};
    }
    return UnknownOption(*app.get_subcommand(first), "boxd " + first, 2, argc, argv);
}

}  // namespace boxd::cli
