/* harness.h — helpers the suites share: parse scene text into a heap arena, set up the
 * scene's view and a frame description, and render one method's frame into a
 * whole-frame mask (and the terms) through the public API. */
#ifndef OM_HARNESS_H
#define OM_HARNESS_H

#include "ombra.h"
#include "ombra_measure.h"

typedef struct h_scene {
    void *mem;
    om_scene s;
} h_scene;

/* Parses `text`; fails the current test (and returns false) on error. */
bool h_scene_parse(h_scene *hs, const char *text);
/* A cloud of 2000 small triangles over a plane, and a long bar above them: at 480x360
 * the hybrid's map leaves 39K samples uncertain, in a tile of 32768 that it cuts into
 * four regions (hybrid_tile.c), every one reached by the bar, and a tile of the rest. */
extern const char h_cloud_bar[];
/* The built-in town's text (om_scene_town_text) in a heap block the caller frees;
 * NULL (the current test failed) when out of memory. */
char *h_town_text(void);
/* The same with a loader for the scene's `mesh` files (NULL: none). */
bool h_scene_parse_ld(h_scene *hs, const char *text, const om_loader *ld);
void h_scene_free(h_scene *hs);
/* Scales scene s about the origin by k, in place: its vertices, bounds, closed shapes'
 * boxes, camera, light and paths, near and far included, so that it draws the same
 * picture at another size. */
void h_scene_scale(om_scene *s, float k);
/* Method `name`'s samples that disagree with ref's (false lit + false shadowed) on
 * the scene `text` scaled by k, w x h, at t 0, with `cfg` (NULL: the method's
 * defaults): what a test of settings that must not depend on the scene's size compares
 * across sizes. UINT64_MAX where the scene or a render fails. */
uint64_t h_scaled_mismatches(const char *text, float k, const char *name, const om_method_cfg *cfg,
                             uint32_t w, uint32_t h);
/* Checks that method `name` at its defaults disagrees with ref on the default scene
 * scaled by 0.001 and by 1000 within 10% as often as at its own size, w x h: its
 * settings are in units that scale with the scene. */
void h_check_scale_free(const char *name, uint32_t w, uint32_t h);

/* Method `method`'s defaults with those settings of `list` ("map=256 asm.cap=1048576")
 * that it takes, so that one list serves a test that loops over the methods. A value
 * out of its range fails the check. */
om_method_cfg h_cfg(const char *method, const char *list);

/* The view from scene s's camera and light at time t, the camera at w x h when w is
 * non-zero (else the scene's size); v->cam and v->light hold them. Returns
 * om_view_init's status (details in d, which may be NULL). */
om_status h_view(om_view *v, const om_scene *s, float t, uint32_t w, uint32_t h, om_diag *d);
/* The origin of that view at time t: a sample's point p is the world point origin + p. */
om_vec3 h_origin(const om_scene *s, float t);

/* *fd zeroed, then scene s, view v, method m with its state, default shading (written
 * to *shade, which must outlive the frame), strips of strip_rows rows (0: the whole
 * frame) into fb. The caller sets the rest: strip callback, clock, parallel-for. */
void h_frame_desc(om_frame_desc *fd, om_shade_cfg *shade, const om_scene *s, const om_view *v,
                  const om_method *m, void *state, om_framebuffer *fb, uint32_t strip_rows);

/* The frame size query (om_frame_bytes) for a width x height image through strips of
 * `rows` rows (0: whole), scene s and method m (each may be NULL), with a parallel-for
 * of `threads` jobs; a spot light. h_frame_least, _bins: its least and with_bins for
 * strips of `rows` rows; h_frame_jobs and h_frame_ids: what its jobs and ids add. */
om_frame_need h_frame_need(const om_method *m, const om_scene *s, uint32_t width, uint32_t height, uint32_t rows,
                           uint32_t threads);
size_t h_frame_least(uint32_t width, uint32_t rows);
size_t h_frame_bins(const om_scene *s, uint32_t width, uint32_t rows);
size_t h_frame_jobs(const om_method *m, const om_scene *s, uint32_t threads);
size_t h_frame_ids(const om_scene *s, uint32_t width, uint32_t height);

/* Renders with method `name` and configuration `cfg` (NULL: defaults; one made for
 * another method: the settings they share, om_method_cfg_from) at the scene's
 * camera (w x h when non-zero) and time t; fills mask[w*h] and, if given, terms and
 * samples. strip_rows 0 = whole frame. Returns the frame's status. */
om_status h_render(const om_scene *s, const char *name, const om_method_cfg *cfg, uint32_t w,
                   uint32_t h, float t, uint32_t strip_rows, uint8_t *mask, om_term *terms,
                   om_sample *samples);
/* The same with a method arena of `method_bytes` (0: the one-pass size). */
om_status h_render_in(const om_scene *s, const char *name, const om_method_cfg *cfg, uint32_t w,
                      uint32_t h, float t, uint32_t strip_rows, size_t method_bytes, uint8_t *mask,
                      om_term *terms, om_sample *samples);

#endif
