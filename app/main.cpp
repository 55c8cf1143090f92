// patchskin: the command line's entry point (app/command_line.h has the
// commands and the exit codes).

#include "app/command_line.h"

int main(int argc, char** argv) { return app::RunCommandLine(argc, argv); }
