/* property/threads.c — many cores, same bits: every method's frame (pixels, terms, mask)
 * and counters with 1, 2, 3, 4, 7 and 16 threads through the platform's pool, and with a
 * parallel-for that runs its jobs backwards, against the inline frame; whole frames and
 * strips, a spot and a directional light, each over a frame arena holding other bytes.
 * And the frame arena: room for N jobs but not N + 1 runs N; the eye pass by parts on
 * threads; triangle ids kept between passes. A method's own threading tests are in its
 * own suite, tests/method/<method>.c. */
#include "../test.h"
#include "../harness.h"
#include "../jobs_util.h"
#include "../../platform/platform.h"

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

void suite_threads(void)
{
    RUN(same_bits);
    RUN(fewer_jobs);
    RUN(eye_halves);
    RUN(kept_ids);
}
