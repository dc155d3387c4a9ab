// Subcommands whose issues have not landed yet: they answer "not implemented yet" with exit 1.
#include <CLI/CLI.hpp>
#include <cstdio>

#include "daemon/cli.h"

namespace boxd::cli {

namespace {

[[maybe_unused]] void AddStub(CLI::App& app, Runner& run, const char* name,
                              const char* description) {
    CLI::App* sub = app.add_subcommand(name, description);
    sub->allow_extras();
    sub->callback([&run, name] {
        run = [name] {
            std::fprintf(stderr, "boxd: %s: not implemented yet\n", name);
            return kExitInternal;
        };
    });
}

}  // namespace

}  // namespace boxd::cli
