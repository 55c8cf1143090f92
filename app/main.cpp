// patchskin: the command line. Parses arguments and dispatches to a subcommand;
// no algorithm lives here. Exit codes, one rule for every command: 0 ok; 2 the
// command cannot run as given (an unknown option, a missing or bad value, a bad
// or unreadable input, an unwritable output); 3 internal error; 128 + N stopped
// by signal N. `compare` and `check` follow idiff instead (0 pass, 1 warning,
// 2 failure, 4 error, usage errors included).

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/bench_command.h"
#include "app/check_command.h"
#include "app/compare_command.h"
#include "app/export_command.h"
#include "app/farm_command.h"
#include "app/elastic_command.h"
#include "app/inspect_command.h"
#include "app/render_command.h"
#include "app/rig_command.h"
#include "app/sheet_command.h"

namespace {
constexpr int kUsageError = 2;  // the same code as a bad value or a bad input file
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"patchskin: motion-capture driven layered skinning and software rendering"};
  app.set_version_flag("--version", std::string("patchskin 0.1.0"));
  app.require_subcommand(0, 1);

  app::InspectOptions inspect_options;
  CLI::App* inspect = app::AddInspectCommand(app, inspect_options);
  app::RenderOptions render_options;
  CLI::App* render = app::AddRenderCommand(app, render_options);
  app::RenderOptions turntable_options;
  turntable_options.camera = "turntable";
  CLI::App* turntable = app::AddTurntableCommand(app, turntable_options);
  app::ExportOptions export_options;
  CLI::App* export_cmd = app::AddExportCommand(app, export_options);
  app::CompareCommandOptions compare_options;
  CLI::App* compare = app::AddCompareCommand(app, &compare_options);
  app::CheckOptions check_options;
  CLI::App* check = app::AddCheckCommand(app, &check_options);
  app::ElasticOptions elastic_options;
  CLI::App* elastic = app::AddElasticCommand(app, elastic_options);
  app::SheetOptions sheet_options;
  CLI::App* sheet = app::AddSheetCommand(app, sheet_options);
  app::FarmOptions farm_options;
  CLI::App* farm = app::AddFarmCommand(app, farm_options);
  app::RigCommandOptions rig_options;
  CLI::App* rig_auto = app::AddRigCommand(app, rig_options);
  app::BenchOptions bench_options;
  CLI::App* bench = app::AddBenchCommand(app, bench_options);

  // idiff's single-dash spellings (-fail ...) become CLI11's (--fail).
  std::vector<std::string> args(argv, argv + argc);
  app::NormalizeIdiffSpelling(args);
  std::vector<char*> arg_ptrs;
  for (std::string& a : args) arg_ptrs.push_back(a.data());
  try {
    app.parse(argc, arg_ptrs.data());
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    if (code == 0) return 0;
    // compare follows idiff: 1 means a warning, so its usage errors are 4.
    if (compare->parsed()) return app::kCompareError;
    return check->parsed() ? app::kCheckError : kUsageError;
  }
  try {
    if (inspect->parsed()) return app::RunInspect(inspect_options);
    if (render->parsed()) return app::RunRender(render_options);
    if (turntable->parsed()) return app::RunRender(turntable_options);
    if (compare->parsed()) return app::RunCompareCommand(compare_options);
    if (check->parsed()) return app::RunCheck(check_options);
    if (export_cmd->parsed()) return app::RunExport(export_options);
    if (elastic->parsed()) return app::RunElastic(elastic_options);
    if (sheet->parsed()) return app::RunSheet(sheet_options);
    if (farm->parsed()) return app::RunFarm(farm_options);
    if (bench->parsed()) return app::RunBench(bench_options);
    if (rig_auto->parsed()) return app::RunRigAuto(rig_options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "patchskin: internal error: %s\n", e.what());
    return 3;
  }
  std::fputs(app.help().c_str(), stdout);
  return 0;
}
