/* shadow.h — what shadow methods share inside the engine: the registry's entries. */
#ifndef OM_SHADOW_H
#define OM_SHADOW_H

#include "../frame/frame.h"

extern const om_method om__method_none;
extern const om_method om__method_ref;
extern const om_method om__method_sm;
extern const om_method om__method_asm;
extern const om_method om__method_rtw;
extern const om_method om__method_spsm;
extern const om_method om__method_izb;
extern const om_method om__method_hybrid;

#endif
