/* commands.h — the `ajar` command's entry: parses argv, runs render, info,
 * devices, help or version, and returns the exit code (commands.c). */
#ifndef AJAR_CLI_COMMANDS_H
#define AJAR_CLI_COMMANDS_H
int cli_main(int argc, char **argv);
#endif
