/* main.c — the `ajar` program (commands.c does the work; tests run the same
 * commands with faults injected, tests/support/ajar_faults.c). */
#include "cli/commands.h"

int main(int argc, char **argv) { return cli_main(argc, argv); }
