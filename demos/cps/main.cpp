// The cps command: the executable's entry; the commands are assembled in cli_main.cpp.
#include "command.h"

int main(int argc, char** argv) { return cps::cli::run_command(argc, argv); }
