// patchskin: the command line. Parses arguments and dispatches to a subcommand;
// no algorithm lives here.

#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

int main(int argc, char** argv) {
  CLI::App app{"patchskin: motion-capture driven layered skinning and software rendering"};
  app.set_version_flag("--version", std::string("patchskin 0.1.0"));
  app.require_subcommand(0, 1);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 1;
  }
  if (app.get_subcommands().empty()) {
    std::fputs(app.help().c_str(), stdout);
  }
  return 0;
}
