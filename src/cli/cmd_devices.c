/* cmd_devices.c — `ajar devices`: the OpenCL devices a render can use. */
#include <stdio.h>
#include <stdlib.h>

#include "ajar.h"
#include "cli/args.h"
#include "cli/commands_shared.h"

/* More OpenCL devices than any machine we know of has. */
#define MAX_DEVICES 256

static void format_bytes(uint64_t b, char *buf, size_t cap)
{
	if (b >= (1ull << 30))
		snprintf(buf, cap, "%.1f GiB", (double)b / (double)(1ull << 30));
	else
		snprintf(buf, cap, "%.0f MiB", (double)b / (double)(1ull << 20));
}

int cmd_devices(int argc, char **argv)
{
	if (argc > 0)
		return args_usage_error("devices: unexpected argument '%s'", argv[0]);
	ajar_device_info *dev = calloc(MAX_DEVICES, sizeof *dev);
	if (!dev) {
		fprintf(stderr, "ajar: error: out of memory\n");
		return EXIT_NO_MEMORY;
	}
	uint32_t n = 0;
	ajar_status st = ajar_devices(dev, MAX_DEVICES, &n);
	if (st != AJAR_OK) {
		report(st, NULL);
		free(dev);
		return exit_code(st);
	}
	if (n == 0) {
		fprintf(stderr, "ajar: error: no OpenCL device found; install an OpenCL driver "
				"(for the CPU: PoCL, Debian package pocl-opencl-icd)\n");
		free(dev);
		return EXIT_DEVICE;
	}
	if (n > MAX_DEVICES)
		n = MAX_DEVICES;
	printf("%-8s %-6s %-40s %s\n", "SELECTOR", "TYPE", "NAME", "COMPUTE UNITS, MEMORY, PLATFORM");
	for (uint32_t i = 0; i < n; i++) {
		char mem[32];
		format_bytes(dev[i].global_memory, mem, sizeof mem);
		printf("%-8s %-6s %-40s %u CU, %s, %s\n", dev[i].selector, dev[i].type, dev[i].name,
		       dev[i].compute_units, mem, dev[i].platform);
	}
	printf("\nSelect one with --device %s (platform:device), --device cpu, --device gpu,\n"
	       "or --device NAME where NAME is any part of a device's name; several at once\n"
	       "with a comma-separated list of these, or --device all.\n",
	       dev[0].selector);
	free(dev);
	return EXIT_OK;
}
