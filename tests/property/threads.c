/* property/threads.c — many cores, same bits: every method's frame (pixels, terms, mask)
 * and counters with 1, 2, 3, 4, 7 and 16 threads through the platform's pool, and with a
 * parallel-for that runs its jobs backwards, against the inline frame; whole frames and
 * strips, a spot and a directional light, each over a frame arena holding other bytes.
 * And the frame arena: room for N jobs but not N + 1 runs N; the eye pass by parts on
 * threads; triangle ids kept between passes. And rtw and spsm together, which share
 * the lent observe: settings that change how they work by bands give the frame of one
 * thread (settings_by_bands), and observe on lent slots leaves the state observe on one
 * thread leaves (observe_lent). A method's other threading tests are in its own suite,
 * tests/method/<method>.c. */
#include "../test.h"
#include "../harness.h"
#include "../jobs_util.h"
#include "../../platform/platform.h"
#include "../../engine/shadow/rtw/rtw.h"
#include "../../engine/shadow/spsm/spsm.h"

#include <stdio.h>
#include <stdlib.h>

static void same_bits(void)
{
    static const uint32_t threads[] = {1, 2, 3, 4, 7, 16};
    om_jobs *pools[6];
    for (int k = 0; k < 6; k++) CHECK_OK(om_jobs_start(&pools[k], threads[k], NULL));
    for (int li = 0; li < 2; li++) {
        const char *text = li ? directional_scene : om_scene_default_text();
        h_scene hs;
        if (!h_scene_parse(&hs, text)) continue;
        for (size_t mi = 0; mi < om_method_count(); mi++) {
            const om_method *m = om_method_at(mi);
            for (uint32_t rows = 0; rows <= 40; rows += 40) {
                frame_out one = render(&hs.s, m, 120, 90, rows, NULL, NULL, 1, 0, true);
                CHECK_MSG(one.st == OM_OK && one.jobs == 1, "%s: inline frame", om_method_name(m));
                for (int k = 0; k < 7; k++) {
                    uint32_t n = k < 6 ? threads[k] : 5;
                    frame_out o = k < 6 ? render(&hs.s, m, 120, 90, rows, om_jobs_for, pools[k], n, h_frame_jobs(m, &hs.s, n), true)
                                        : render(&hs.s, m, 120, 90, rows, backwards, NULL, n, h_frame_jobs(m, &hs.s, n), true);
                    CHECK_MSG(o.st == OM_OK && o.jobs == n, "%s: %u jobs ran %u", om_method_name(m), n, o.jobs);
                    CHECK_MSG(o.hash == one.hash, "%s light %d strips %u: %u threads%s change the frame",
                              om_method_name(m), li, rows, n, k < 6 ? "" : " backwards");
                    CHECK_MSG(!memcmp(o.ms.counters, one.ms.counters, sizeof o.ms.counters),
                              "%s: %u threads change the counters", om_method_name(m), n);
                }
            }
        }
        h_scene_free(&hs);
    }
    for (int k = 0; k < 6; k++) om_jobs_stop(pools[k]);
}

/* A frame arena with room for 3 jobs runs 3 when 8 are asked for (the bins of a whole
 * frame kept beside them), and one (inline) with room for fewer than 2. */
static void fewer_jobs(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    const om_method *m = om_method_find("ref");
    frame_out one = render(&hs.s, m, 64, 48, 0, NULL, NULL, 1, 0, true);
    frame_out three = render(&hs.s, m, 64, 48, 0, backwards, NULL, 8, h_frame_jobs(m, &hs.s, 3), true);
    frame_out three_nobins = render(&hs.s, m, 64, 48, 0, backwards, NULL, 8, h_frame_jobs(m, &hs.s, 3), false);
    frame_out none = render(&hs.s, m, 64, 48, 0, backwards, NULL, 8, h_frame_jobs(m, &hs.s, 1), false);
    CHECK_EQ_U(three.jobs, 3);
    CHECK_EQ_U(three_nobins.jobs, 3);
    CHECK_EQ_U(none.jobs, 1);
    CHECK(three.hash == one.hash && three_nobins.hash == one.hash && none.hash == one.hash);
    CHECK_EQ_U(h_frame_jobs(m, &hs.s, 1), 0);
    CHECK(h_frame_jobs(m, &hs.s, 4) == 2 * h_frame_jobs(m, &hs.s, 2));
    /* sm's map by bands, with the light's bins and without (one band a job) */
    const om_method *sm = om_method_find("sm");
    frame_out sm1 = render(&hs.s, sm, 64, 48, 0, NULL, NULL, 1, 0, true);
    frame_out sm3 = render(&hs.s, sm, 64, 48, 0, backwards, NULL, 3, h_frame_jobs(sm, &hs.s, 3), false);
    frame_out sm3_lean = render(&hs.s, sm, 64, 48, 0, backwards, NULL, 3, h_frame_jobs(sm, NULL, 3), false);
    CHECK(sm3.jobs == 3 && sm3_lean.jobs == 3);
    CHECK(sm3.hash == sm1.hash && sm3_lean.hash == sm1.hash);
    h_scene_free(&hs);
}

/* A worker index for `backwards` that names the thread *host says. */
static uint32_t named(void *host)
{
    return *(const uint32_t *)host;
}

/* One strip on two jobs and a scene of more than one vertex for every 8 pixels: the
 * eye pass rasterizes by parts of the triangles (frame.c), the halves, or with the
 * host's worker index many parts, each into its thread's target. Two planes that
 * coincide, one in each half: where they tie the first one's colour wins, as in one
 * walk of every triangle, whichever target holds which part and in whatever order
 * they are drawn (every part in one target, drawn last to first, leaves the tie to the
 * depth test); and no bins are carved (the frame arena's peak is the same with room
 * for them and without). Three jobs (with the bins) give the same frame. */
static void eye_halves(void)
{
    static const char two_planes[] =
        "camera eye 0 4 4 target 0 0 0 fov 60\n"
        "light spot pos 0 6 0 target 0 0 0 fov 90\n"
        "plane size 4 4 albedo 1 0 0\n"
        "plane size 4 4 albedo 0 0 1\n";
    h_scene hs;
    if (!h_scene_parse(&hs, two_planes)) return;
    const om_method *m = om_method_find("none");
    const size_t two_b = h_frame_jobs(m, &hs.s, 2), three_b = h_frame_jobs(m, &hs.s, 3);
    frame_out one = render(&hs.s, m, 8, 6, 0, NULL, NULL, 1, 0, true);
    frame_out two = render(&hs.s, m, 8, 6, 0, backwards, NULL, 2, two_b, true);
    frame_out lean = render(&hs.s, m, 8, 6, 0, backwards, NULL, 2, two_b, false);
    frame_out three = render(&hs.s, m, 8, 6, 0, backwards, NULL, 3, three_b, true);
    CHECK(two.jobs == 2 && lean.jobs == 2 && three.jobs == 3);
    CHECK(two.hash == one.hash && lean.hash == one.hash && three.hash == one.hash);
    CHECK_EQ_U(two.peak, lean.peak);
    uint32_t calls = 0, first = 0, second = 1;
    om_jobs *pool = NULL;
    CHECK_OK(om_jobs_start(&pool, 2, NULL));
    const frame_out spread = render_on(&hs.s, m, "map=512", 8, 6, 0, backwards, &calls, rotating, 2, two_b, true);
    const frame_out in0 = render_on(&hs.s, m, "map=512", 8, 6, 0, backwards, &first, named, 2, two_b, true);
    const frame_out in1 = render_on(&hs.s, m, "map=512", 8, 6, 0, backwards, &second, named, 2, two_b, true);
    const frame_out pooled = render_on(&hs.s, m, "map=512", 8, 6, 0, om_jobs_for, pool, om_jobs_worker, 2, two_b, true);
    CHECK(spread.jobs == 2 && in0.jobs == 2 && in1.jobs == 2 && pooled.jobs == 2);
    CHECK(spread.hash == one.hash && in0.hash == one.hash && in1.hash == one.hash && pooled.hash == one.hash);
    om_jobs_stop(pool);
    h_scene_free(&hs);
}

/* A frame through strips that passes over the image more than once (asm and rtw
 * observe; a directional light is fitted) keeps its first pass's triangle ids where the
 * arena has om_frame_bytes' with_ids beyond the rest, and its later passes resolve from them:
 * the same frames and counters as without the room, inline and with jobs; a frame that
 * passes once (sm under the spot light) carves none. */
static void kept_ids(void)
{
    static const char *const names[] = {"asm", "rtw", "sm"};
    for (int li = 0; li < 2; li++) {
        h_scene hs;
        if (!h_scene_parse(&hs, li ? directional_scene : om_scene_default_text())) continue;
        const size_t ids = h_frame_ids(&hs.s, 120, 90);
        CHECK(ids >= 120 * 90 * 2);
        for (int mi = 0; mi < 3; mi++) {
            const om_method *m = om_method_find(names[mi]);
            const bool twice = li || mi < 2;
            for (uint32_t rows = 8; rows <= 40; rows += 32)
                for (uint32_t n = 1; n <= 3; n += 2) {
                    const size_t jb = h_frame_jobs(m, &hs.s, n);
                    om_parallel_for_fn pf = n > 1 ? backwards : NULL;
                    frame_out a = render(&hs.s, m, 120, 90, rows, pf, NULL, n, jb, true);
                    frame_out b = render(&hs.s, m, 120, 90, rows, pf, NULL, n, jb + ids, true);
                    CHECK_MSG(a.st == OM_OK && b.st == OM_OK && a.hash == b.hash,
                              "%s light %d strips %u threads %u: kept ids change the frame", om_method_name(m), li, rows, n);
                    CHECK_MSG(!memcmp(a.ms.counters, b.ms.counters, sizeof a.ms.counters),
                              "%s: kept ids change the counters", om_method_name(m));
                    CHECK_MSG(twice ? b.peak >= a.peak + 120 * 90 * 2 : b.peak == a.peak,
                              "%s light %d: ids carved %s", om_method_name(m), li, twice ? "not" : "needlessly");
                }
        }
        h_scene_free(&hs);
    }
}

/* Settings that change how a method works by bands, on 2 and 5 backwards jobs, whole
 * and through strips of 40, against the inline frame (frame and counters):
 *  - rtw's warped map by bands: the exact map (with the light's bins, which pass over
 *    the triangles that miss a band's grid rows, and without: the counters hold the
 *    triangles drawn, counted in the band of a triangle's first grid row), the warped
 *    vertices' map (the first band makes it whole), forward analysis;
 *  - spsm's map by bands (a triangle touching one texel row of the whole map, not of
 *    its band, takes its nearest vertex's depth; the fine map's rows are two of the
 *    map's; with the light's bins and without) and its resolve by bands with AA (its
 *    sub-samples' steps must not come from the next row, which another band holds),
 *    with the fine plain map, its points all made or only those the lookup reads. */
static void settings_by_bands(void)
{
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    static const char *const sets[][2] = {
        {"rtw", "map=512"}, {"rtw", "map=300 rtw.exact=0"}, {"rtw", "map=256 rtw.analysis=2 rtw.sigma=0"},
        {"spsm", "map=256 spsm.aa=4"}, {"spsm", "map=512 spsm.aa=3 spsm.fine=1 spsm.records=1"},
        {"spsm", "map=1024 spsm.fine=1 spsm.records=2"}, {"spsm", "map=64"},
    };
    for (size_t i = 0; i < sizeof sets / sizeof sets[0]; i++) {
        const om_method *m = om_method_find(sets[i][0]);
        for (uint32_t rows = 0; rows <= 40; rows += 40) {
            frame_out one = render_set(&hs.s, m, sets[i][1], 96, 72, rows, NULL, NULL, 1, 0, true);
            CHECK_MSG(one.st == OM_OK, "%s %s: inline frame", om_method_name(m), sets[i][1]);
            for (uint32_t n = 2; n <= 5; n += 3)
                for (int lean = 0; lean < (rows ? 1 : 2); lean++) {   /* strips' bins come first */
                    frame_out o = render_set(&hs.s, m, sets[i][1], 96, 72, rows, backwards, NULL, n,
                                             h_frame_jobs(m, lean ? NULL : &hs.s, n), !lean);
                    CHECK_MSG(o.st == OM_OK && o.jobs == n, "%s %s strips %u%s: %u jobs ran %u", om_method_name(m), sets[i][1], rows, lean ? " lean" : "", n, o.jobs);
                    CHECK_MSG(o.hash == one.hash, "%s %s strips %u: %u bands%s change the frame", om_method_name(m),
                              sets[i][1], rows, n, lean ? " without bins" : "");
                    CHECK_MSG(!memcmp(o.ms.counters, one.ms.counters, sizeof o.ms.counters),
                              "%s %s strips %u: %u bands change the counters", om_method_name(m), sets[i][1], rows, n);
                }
        }
    }
    h_scene_free(&hs);
}

/* rtw's and spsm's observe on three lent slots (in reverse slot order), whole and in
 * strips of 8 rows: the bands did run (their slots hold work to fold after observe),
 * and after build the state's importance map and seen bits (rtw) and the texels the
 * build reads (spsm's need) are those of observe on the calling thread. */
static void observe_lent(void)
{
    enum { W = 96, H = 72 };
    h_scene hs;
    if (!h_scene_parse(&hs, om_scene_default_text())) return;
    uint32_t *depth = calloc((size_t)W * H, sizeof *depth), *id = calloc((size_t)W * H, sizeof *id);
    om_sample *smp = calloc((size_t)W * H, sizeof *smp);
    om_term *terms = calloc((size_t)W * H, sizeof *terms);
    static const char *const sets[][2] = {{"rtw", "map=256"}, {"spsm", "map=256 spsm.records=2"}};
    for (int i = 0; i < 2; i++) {
        const om_method *m = om_method_find(sets[i][0]);
        const om__pass *ps = m->pass;
        CHECK(ps && ps->lend && !ps->job);
        if (!ps) continue;
        om_method_cfg c = h_cfg(sets[i][0], sets[i][1]);
        size_t mn, full;
        om_diag d;
        CHECK_OK(om_method_bytes(m, &c, &hs.s, W, H, &mn, &full));
        uint64_t hash[2][2] = {{0}};
        for (int lend = 0; lend < 2; lend++)
            for (uint32_t rows = 8; rows <= H; rows += H - 8) {
                void *mm = calloc(1, full), *state = NULL;
                om_arena ma;
                om_arena_init(&ma, mm, full, "method");
                CHECK_OK(om_method_init(m, &state, &ma, &c, &hs.s, W, H, &d));
                lent3 h;
                const size_t sb = ps->scratch(state, &hs.s);
                CHECK(sb > 0);
                for (int k = 0; k < 3; k++) h.slot[k] = calloc(1, sb ? sb : 1);
                const om__lend l = {lent_run, lent_run, &h, 3};
                om_view v;
                CHECK_OK(h_view(&v, &hs.s, 0.0f, W, H, &d));
                om_target tg = {W, H, 0, H, depth, id};
                om_strip st = {W, H, 0, H, smp, terms, v.origin};
                om__eye_pass_mark(&hs.s, &v, &tg, &st, NULL);
                ps->lend(state, lend ? &l : NULL);
                CHECK_OK(m->begin(state, &v, &d));
                for (uint32_t y = 0; y < H; y += rows) {
                    om_strip sub = {W, H, y, y + rows > H ? H - y : rows, smp + (size_t)y * W, terms + (size_t)y * W, v.origin};
                    CHECK_OK(m->observe(state, &sub, &d));
                }
                const om__lent *lt = i ? &((const om__spsm_state *)state)->lent : &((const om__rtw *)state)->lent;
                CHECK_MSG(lt->used == (lend == 1), "%s: bands %s", om_method_name(m), lend ? "did not run" : "ran unlent");
                CHECK_OK(m->build(state, &d));
                if (i == 0) {
                    const om__rtw *r = (const om__rtw *)state;
                    const size_t nn = (size_t)r->n * r->n;
                    hash[lend][rows == H] = om_hash(om_hash(0, r->imp, nn * sizeof *r->imp), r->seen, (nn + 7) / 8);
                } else {
                    const om__spsm_state *sp = (const om__spsm_state *)state;
                    hash[lend][rows == H] = om_hash(0, sp->need, (size_t)sp->size * sp->words * sizeof *sp->need);
                }
                ps->lend(state, NULL);
                for (int k = 0; k < 3; k++) free(h.slot[k]);
                free(mm);
            }
        CHECK_MSG(hash[1][0] == hash[0][0] && hash[1][1] == hash[0][1], "%s: lent observe differs", om_method_name(m));
    }
    free(depth);
    free(id);
    free(smp);
    free(terms);
    h_scene_free(&hs);
}

void suite_threads(void)
{
    RUN(same_bits);
    RUN(fewer_jobs);
    RUN(eye_halves);
    RUN(kept_ids);
    RUN(settings_by_bands);
    RUN(observe_lent);
}
