/* default.c — the built-in scenes, as text in the scene format: the default scene,
 * what `ombra render` shows without a scene file and the scene the tests and
 * benchmarks know best, and its small twin for microcontrollers: the same
 * composition, the curved shapes with fewer facets, under 2,000 triangles.
 * After the Adaptive Shadow Maps walkthrough: objects of very different scales (a 4 m
 * block down to 0.2 m cubes and 5 cm fence bars) on a wide floor, lit by a distant,
 * wide-angle spot light, so one uniform shadow map cannot resolve every shadow well. */
#include "scene.h"

/* One text, two tessellations: the floor's divisions, the two large spheres', the
 * pillar's, the small ball's and the pole's segments. */
#define SCENE_TEXT(NAME, TRIS, FLOOR, SPHERE, PILLAR, BALL, POLE) \
    "# ombra " NAME " scene: objects of very different scales on a 60 m floor,\n" \
    "# lit by a distant wide-angle spot light (" TRIS " triangles).\n" \
    "\n" \
    "camera eye 0 2.5 12 target 0 0.8 0 fov 55 size 640 480 near 0.1 far 200\n" \
    "# Far away and wide: its square frustum covers the whole floor, so texels are\n" \
    "# large where the camera looks closely (the fence, the small cubes). Low and\n" \
    "# behind the objects, so their long shadows fall towards the camera.\n" \
    "light spot pos 40 40 -60 target -3 0 3 fov 70 near 20 far 200\n" \
    "\n" \
    "material concrete albedo 0.75 0.74 0.70\n" \
    "material brick albedo 0.70 0.42 0.32\n" \
    "material stone albedo 0.55 0.53 0.48\n" \
    "material wood albedo 0.62 0.46 0.28\n" \
    "material metal albedo 0.60 0.62 0.66\n" \
    "\n" \
    "plane size 60 60 divisions " FLOOR " material concrete\n" \
    "\n" \
    "# large: a 4 m building-like block\n" \
    "box size 4 4 4 translate -7 2 -8 material brick\n" \
    "\n" \
    "# medium: boxes, a pillar, a finely tessellated sphere and a flattened boulder\n" \
    "box size 1 1 1 rotate 0 25 0 translate 2 0.5 -4 albedo 0.80 0.70 0.30\n" \
    "box size 1.5 0.8 1 translate -3 0.4 -3 albedo 0.35 0.55 0.35\n" \
    "box size 0.8 2 0.8 rotate 0 -15 0 translate 6 1 -2 material brick\n" \
    "sphere radius 1.2 segments " SPHERE " translate 0 1.2 -2 albedo 0.85 0.85 0.90\n" \
    "sphere radius 1 segments " SPHERE " scale 1.5 0.6 1 rotate 0 30 0 translate 5 0.6 -6 material stone\n" \
    "cylinder radius 0.4 height 3 segments " PILLAR " translate 3.5 0 -0.5 material metal\n" \
    "\n" \
    "# small: 0.2 m cubes (one stacked), a small ball and a thin pole\n" \
    "box size 0.2 0.2 0.2 translate -1 0.1 3 material wood\n" \
    "box size 0.2 0.2 0.2 rotate 0 30 0 translate -1 0.3 3 material wood\n" \
    "box size 0.2 0.2 0.2 translate -0.5 0.1 3.5 material wood\n" \
    "box size 0.2 0.2 0.2 rotate 0 45 0 translate 0.6 0.1 3.2 material wood\n" \
    "box size 0.2 0.2 0.2 translate 1.0 0.1 2.6 material wood\n" \
    "box size 0.2 0.2 0.2 rotate 0 10 0 translate 0.2 0.1 4.2 material wood\n" \
    "sphere radius 0.25 segments " BALL " translate 1.8 0.25 1.5 albedo 0.90 0.20 0.15\n" \
    "cylinder radius 0.03 height 2.5 segments " POLE " translate -2.5 0 1 material metal\n" \
    "\n" \
    "# a fence of ten 5 cm bars with a top rail: thin shadows, easily lost\n" \
    "box size 0.05 1.2 0.05 translate -6.0 0.6 0.5 material wood\n" \
    "box size 0.05 1.2 0.05 translate -5.7 0.6 0.5 material wood\n" \
    "box size 0.05 1.2 0.05 translate -5.4 0.6 0.5 material wood\n" \
    "box size 0.05 1.2 0.05 translate -5.1 0.6 0.5 material wood\n" \
    "box size 0.05 1.2 0.05 translate -4.8 0.6 0.5 material wood\n" \
    "box size 0.05 1.2 0.05 translate -4.5 0.6 0.5 material wood\n" \
    "box size 0.05 1.2 0.05 translate -4.2 0.6 0.5 material wood\n" \
    "box size 0.05 1.2 0.05 translate -3.9 0.6 0.5 material wood\n" \
    "box size 0.05 1.2 0.05 translate -3.6 0.6 0.5 material wood\n" \
    "box size 0.05 1.2 0.05 translate -3.3 0.6 0.5 material wood\n" \
    "box size 2.8 0.05 0.05 translate -4.65 1.175 0.5 material wood\n" \
    "\n" \
    "# semi-transparent: a blue-tinted glass pane, its shadow tinted, not black\n" \
    "box size 1.6 1.6 0.05 rotate 0 40 0 translate 1.5 0.8 -0.5 albedo 0.30 0.60 0.90 opacity 0.5\n" \
    "\n" \
    "# a slow walk around the objects (t in seconds)\n" \
    "key camera 0 eye 0 2.5 12 target 0 0.8 0\n" \
    "key camera 1 eye 7 2.2 9 target 0 0.8 -1\n" \
    "key camera 2 eye 11 2.8 1 target 0 0.8 -2\n" \
    "key camera 3 eye 8 3.5 -10 target 0 0.8 -3\n" \
    "key camera 4 eye 0 4 -14 target 0 0.8 -2\n" \
    "# the light drifts a little: shadows must not flicker as it moves\n" \
    "key light 0 pos 40 40 -60 target -3 0 3\n" \
    "key light 4 pos 46 40 -55 target -3 0 3\n"

const char *om_scene_default_text(void)
{
    return SCENE_TEXT("default", "about 23K", "8", "96 rings 48", "128", "64 rings 32", "16");
}

const char *om_scene_small_text(void)
{
    return SCENE_TEXT("small", "about 1.6K", "4", "24 rings 12", "24", "12 rings 6", "8");
}
