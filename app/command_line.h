#pragma once
// The command line: every subcommand's options, declared and parsed here only
// (CLI11 is included by command_line.cpp alone; the commands take plain option
// structs). Exit codes, one rule for every command: 0 ok; 2 the command cannot
// run as given (an unknown option, a missing or bad value, a bad or unreadable
// input, an unwritable output); 3 internal error; 128 + N stopped by signal N.
// `compare` and `check` follow idiff instead (0 pass, 1 warning, 2 failure,
// 4 error, usage errors included).

#include <optional>
#include <string>
#include <vector>

#include "app/render_command.h"

namespace app {

// Parses argv, runs the subcommand it names, and returns the process exit code.
int RunCommandLine(int argc, char** argv);

// Parses `words` as the options of `patchskin render INPUT WORDS...` into `out`
// (`out.given` lists the options set). Returns the parser's message when they
// do not parse; --help is refused, as it is not a render setting.
std::optional<std::string> ParseRenderWords(const std::string& input,
                                            const std::vector<std::string>& words,
                                            RenderOptions& out);

}  // namespace app
