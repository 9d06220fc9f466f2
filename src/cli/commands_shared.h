/* commands_shared.h — what the command files share (cli_common.c): the
 * message prefix, exit codes from statuses, error reports, loading a
 * scene, checking an output, the scene options, the found portals' lines;
 * and each command's entry (cmd_render.c, cmd_info.c, cmd_devices.c). */
#ifndef AJAR_CLI_COMMANDS_SHARED_H
#define AJAR_CLI_COMMANDS_SHARED_H
#include <stdint.h>

#include "ajar.h"
#include "cli/args.h"

/* Under mpirun (ajar_mpi_init): "ajar: " on rank 0, "ajar: rank N (host): "
 * elsewhere, so a message from another machine says where it came from. */
extern char g_prefix[128];
extern const char usage_render[];

int exit_code(ajar_status st);
/* Prints the library's message for a failure about `file` (prefixing the
 * file name when the message does not already name it). */
void report(ajar_status st, const char *file);
/* Loads a scene; a scene that cannot be read is bad input (exit 2) even
 * when the library calls it an I/O error: exit 4 is for outputs. */
int load_scene(const char *path, int allow_outside_files, ajar_scene **scene);
/* Before spending minutes on a render: can `path` be created? Checks the
 * directory only, and creates nothing. */
int check_output(const char *opt, const char *path);
/* The command line's sky and sun (SceneArgs) into the loaded scene. A
 * file named there is the user's choice: not confined to the scene's
 * folder. */
int apply_scene_args(ajar_scene *scene, const SceneArgs *sc);

/* The portals found, up to FOUND_MAX of them. */
#define FOUND_MAX 64
void print_found(const ajar_portal *p, uint32_t n);

/* Under mpirun every rank runs this with the same arguments: rank 0 checks
 * the outputs, reads a checkpoint, prints and writes; every rank loads the
 * scene and renders on its own devices (ajar.h, "Several machines"); a
 * failure on any rank before the render is agreed on (ajar_mpi_agree), so
 * every rank stops with the same exit code. */
int cmd_render(int argc, char **argv);
int cmd_devices(int argc, char **argv);
int cmd_info(int argc, char **argv);

#endif
