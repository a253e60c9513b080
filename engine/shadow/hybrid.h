/* hybrid.h — the hybrid exact method's map lookup, for the tests that hold each of
 * its certain answers against the predicate (hybrid.c has the method and the proof). */
#ifndef OM_HYBRID_H
#define OM_HYBRID_H

#include "occlude.h"

/* Classifies a sample of the current frame (after the method's build) by the map
 * alone: 1 certainly lit, 2 certainly shadowed (t set to 0), 0 uncertain. */
int om__hybrid_decide(void *state, const om__lpoint *p, om_term *t);
/* The state's light space, to project the samples to classify. */
const om__lspace *om__hybrid_lspace(const void *state);

#endif
