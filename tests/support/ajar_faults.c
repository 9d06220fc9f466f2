/* ajar_faults.c — the `ajar` command with faults injected into the
 * library's device passes (src/render/render_overrides.h), for tests that
 * run it in other processes (under mpirun, test_mpi). The faults come from
 * this program's environment, which the library itself never reads:
 *   AJAR_TEST_FAIL_DEVICE=<device>:<pass>[:lost]  pass <pass> (from 1) of
 *       device <device> (from 0, in selection order) fails at launch, or
 *       with ":lost" after its kernel ran;
 *   AJAR_TEST_PASS_SPP=N  every pass renders at most N samples per pixel.
 * Without them it is the `ajar` command. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/commands.h"
#include "render/render_overrides.h"

int main(int argc, char **argv)
{
	const char *fail = getenv("AJAR_TEST_FAIL_DEVICE"), *spp = getenv("AJAR_TEST_PASS_SPP");
	unsigned device, pass;
	char mode[8] = "";
	if (fail && sscanf(fail, "%u:%u:%7s", &device, &pass, mode) >= 2) {
		render_faults.device = device;
		render_faults.pass = pass;
		render_faults.lost = strcmp(mode, "lost") == 0;
	}
	if (spp)
		render_faults.pass_spp = (uint32_t)strtoul(spp, NULL, 10);
	return cli_main(argc, argv);
}
