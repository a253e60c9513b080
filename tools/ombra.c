/* ombra.c — the `ombra` command: dispatches to its subcommands. */
#include "cli.h"

#include <string.h>

static const char usage[] =
    "usage: ombra <command> [options]\n"
    "\n"
    "Hard shadows on small machines: renders a scene with a shadow method inside the\n"
    "memory it is given, and writes PPM/PGM files.\n"
    "\n"
    "commands:\n"
    "  render [SCENE]   render a frame (the built-in default scene without SCENE)\n"
    "  info [SCENE]     triangles, bounds, and the bytes each method would need\n"
    "  compare A B      compare two shadow masks (PGM), A the reference\n"
    "  bench            sweep the methods' settings: CSV and SVG charts of accuracy\n"
    "                   against time and memory\n"
    "  report           the sweep as one HTML page: charts, table, crops\n"
    "  methods          list the shadow methods\n"
    "  scene            print the built-in default scene (a start for your own)\n"
    "\n"
    "'ombra <command> --help' describes a command's options.\n";

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") ||
        !strcmp(argv[1], "help")) {
        fputs(usage, argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    if (!strcmp(argv[1], "render")) return cmd_render(argc - 1, argv + 1);
    if (!strcmp(argv[1], "info")) return cmd_info(argc - 1, argv + 1);
    if (!strcmp(argv[1], "compare")) return cmd_compare(argc - 1, argv + 1);
    if (!strcmp(argv[1], "bench")) return cmd_bench(argc - 1, argv + 1);
    if (!strcmp(argv[1], "report")) return cmd_report(argc - 1, argv + 1);
    if (!strcmp(argv[1], "scene")) {
        fputs(om_scene_default_text(), stdout);
        return 0;
    }
    if (!strcmp(argv[1], "methods")) {
        for (size_t i = 0; i < om_method_count(); i++)
            printf("%-6s %s\n", om_method_at(i)->name, om_method_at(i)->summary);
        size_t n;
        const om_cfg_field *f = om_method_cfg_fields(&n);
        om_method_cfg c;
        om_method_cfg_default(&c);
        printf("\nsettings (--set NAME=VALUE):\n");
        for (size_t i = 0; i < n; i++) {
            const unsigned char *p = (const unsigned char *)&c + f[i].offset;
            double v;
            if (f[i].kind == 'u') { uint32_t u; memcpy(&u, p, sizeof u); v = u; }
            else if (f[i].kind == 'z') { uint64_t u; memcpy(&u, p, sizeof u); v = (double)u; }
            else { float x; memcpy(&x, p, sizeof x); v = x; }
            printf("  %-15s %-11.9g %s\n", f[i].name, v, f[i].help);
        }
        return 0;
    }
    fprintf(stderr, "ombra: unknown command '%s'\n\n%s", argv[1], usage);
    return 2;
}
