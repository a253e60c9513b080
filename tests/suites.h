/* suites.h — the list of test suites, in the order they run: each file of tests/unit/
 * (one an engine module), tests/method/ (one a method) and tests/property/ defines one. */
#ifndef OM_SUITES_H
#define OM_SUITES_H
#ifndef OM_SUITES
#define OM_SUITES \
    X(suite_core) \
    X(suite_scene) \
    X(suite_obj) \
    X(suite_scene_fuzz) \
    X(suite_raster) \
    X(suite_hiz) \
    X(suite_scene_raster) \
    X(suite_frame) \
    X(suite_measure) \
    X(suite_platform) \
    X(suite_settings) \
    X(suite_shadow_common) \
    X(suite_ref) \
    X(suite_sm) \
    X(suite_csm) \
    X(suite_asm) \
    X(suite_rtw) \
    X(suite_spsm) \
    X(suite_izb) \
    X(suite_hybrid) \
    X(suite_methods) \
    X(suite_oracle) \
    X(suite_oracle_far) \
    X(suite_far) \
    X(suite_robust) \
    X(suite_threads) \
    X(suite_objects) \
    /* end of list */
#endif
#define X(suite) void suite(void);
OM_SUITES
#undef X
#endif
