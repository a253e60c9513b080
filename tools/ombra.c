/* ombra.c — the `ombra` command: dispatches to its subcommands. */
#include "cli.h"

#include <stdlib.h>
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
    "  scene            print a built-in scene: the default one (a start for your\n"
    "                   own), its small twin or the town\n"
    "\n"
    "'ombra <command> --help' describes a command's options; 'ombra --version' prints\n"
    "the version.\n";

static const char methods_help[] =
    "usage: ombra methods\n"
    "\n"
    "Lists the shadow methods and every setting ('--set NAME=VALUE') with its default.\n";

static const char scene_help[] =
    "usage: ombra scene [--small | --town]\n"
    "\n"
    "Prints the built-in default scene in the scene format: a start for your own.\n"
    "  --small   its twin for microcontrollers: the same objects in 1,600 triangles\n"
    "  --town    the town: 514 houses, towers, walls, lamps and trees (10,100\n"
    "            triangles) over a ground a kilometre across, seen from its main\n"
    "            street under a low sun, with a walk down the street\n";

/* A setting's default as it would be written: the shortest decimal that reads back
 * as the same float (0.01, not 0.00999999978). */
static void format_value(const om_setting *f, char *buf, size_t n)
{
    if (f->kind != OM_SETTING_F32) { snprintf(buf, n, "%.0f", f->def); return; }
    const float x = (float)f->def;
    for (int prec = 1; prec <= 9; prec++) {
        snprintf(buf, n, "%.*g", prec, (double)x);
        if (strtof(buf, NULL) == x) return;
    }
}

/* Whether setting i of method k is the first of that name (several methods take "map"). */
static bool first_of_name(size_t k, uint32_t i)
{
    const char *name = om_method_setting_at(om_method_at(k), i)->name;
    for (size_t j = 0; j < k; j++)
        if (om_method_setting(om_method_at(j), name)) return false;
    return true;
}

static int list_methods(void)
{
    size_t wn = 0, wv = 0;
    char v[32];
    for (size_t k = 0; k < om_method_count(); k++) {
        const om_method *m = om_method_at(k);
        printf("%-6s %s\n", om_method_name(m), om_method_summary(m));
        for (uint32_t i = 0; i < om_method_nsettings(m); i++) {
            format_value(om_method_setting_at(m, i), v, sizeof v);
            if (strlen(om_method_setting_at(m, i)->name) > wn) wn = strlen(om_method_setting_at(m, i)->name);
            if (strlen(v) > wv) wv = strlen(v);
        }
    }
    /* every setting once, with its default and the methods that take it */
    printf("\nsettings (--set NAME=VALUE):\n");
    for (size_t k = 0; k < om_method_count(); k++) {
        const om_method *m = om_method_at(k);
        for (uint32_t i = 0; i < om_method_nsettings(m); i++) {
            const om_setting *f = om_method_setting_at(m, i);
            if (!first_of_name(k, i)) continue;
            format_value(f, v, sizeof v);
            printf("  %-*s  %-*s  %s (", (int)wn, f->name, (int)wv, v, f->doc);
            for (size_t j = k, sep = 0; j < om_method_count(); j++)
                if (om_method_setting(om_method_at(j), f->name))
                    printf("%s%s", sep++ ? ", " : "", om_method_name(om_method_at(j)));
            printf(")\n");
        }
    }
    return 0;
}

/* A subcommand without options: --help prints its help, anything else is refused. */
static int no_options(int argc, char **argv, const char *help, int (*run)(void))
{
    if (argc > 2) {
        if (!strcmp(argv[2], "--help") || !strcmp(argv[2], "-h")) { fputs(help, stdout); return 0; }
        return cli_usage_error(argv[1], "takes no arguments; unexpected '%s'", argv[2]);
    }
    return run();
}

static int print_scene(int argc, char **argv)
{
    if (argc > 2 && (!strcmp(argv[2], "--help") || !strcmp(argv[2], "-h"))) { fputs(scene_help, stdout); return 0; }
    const bool small = argc > 2 && !strcmp(argv[2], "--small"), town = argc > 2 && !strcmp(argv[2], "--town");
    if (argc > 3 || (argc == 3 && !small && !town))
        return cli_usage_error("scene", "takes only --small or --town; unexpected '%s'", argv[argc > 3 && (small || town) ? 3 : 2]);
    if (!town) {
        fputs(small ? om_scene_small_text() : om_scene_default_text(), stdout);
        return 0;
    }
    const size_t len = om_scene_town_text(NULL, 0);
    char *text = malloc(len + 1);
    if (!text) {
        om_diag d;
        return cli_error(NULL, &d, cli_oom(&d));
    }
    om_scene_town_text(text, len + 1);
    fputs(text, stdout);
    free(text);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") ||
        !strcmp(argv[1], "help")) {
        fputs(usage, argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    if (!strcmp(argv[1], "--version") || !strcmp(argv[1], "-V")) {
        printf("ombra %s\n", om_version());
        return 0;
    }
    if (!strcmp(argv[1], "render") || !strcmp(argv[1], "bench")) {
        int rc = !strcmp(argv[1], "render") ? cmd_render(argc - 1, argv + 1) : cmd_bench(argc - 1, argv + 1);
        cli_threads_stop();
        return rc;
    }
    if (!strcmp(argv[1], "info")) return cmd_info(argc - 1, argv + 1);
    if (!strcmp(argv[1], "compare")) return cmd_compare(argc - 1, argv + 1);
    if (!strcmp(argv[1], "report")) return cmd_report(argc - 1, argv + 1);
    if (!strcmp(argv[1], "scene")) return print_scene(argc, argv);
    if (!strcmp(argv[1], "methods")) return no_options(argc, argv, methods_help, list_methods);
    fprintf(stderr, "ombra: unknown command '%s'\n\n%s", argv[1], usage);
    return 2;
}
