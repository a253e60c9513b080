/* config.h — every compile-time switch of the engine, with its default, in one place.
 * Each is 0 or 1 (or, for OM_ALLOW_EXCESS_PRECISION, defined or not) and is set with
 * -D on the compiler's command line; core.h includes this header, so every engine file
 * sees the same values. No switch changes a frame's bits, except where its own line
 * says so. */
#ifndef OM_CONFIG_H
#define OM_CONFIG_H

/* OM_WITH_NONE, _REF, _SM, _CSM, _ASM, _RTW, _SPSM, _IZB, _HYBRID (1): whether the method is
 * built in. registry.c is the only file that reads them: a method left out is not in
 * its list, so a program linked against the library carries none of its code (a
 * firmware may compile registry.c alone with some of them 0, ahead of the library). */
#ifndef OM_WITH_NONE
#define OM_WITH_NONE 1
#endif
#ifndef OM_WITH_REF
#define OM_WITH_REF 1
#endif
#ifndef OM_WITH_SM
#define OM_WITH_SM 1
#endif
#ifndef OM_WITH_CSM
#define OM_WITH_CSM 1
#endif
#ifndef OM_WITH_ASM
#define OM_WITH_ASM 1
#endif
#ifndef OM_WITH_RTW
#define OM_WITH_RTW 1
#endif
#ifndef OM_WITH_SPSM
#define OM_WITH_SPSM 1
#endif
#ifndef OM_WITH_IZB
#define OM_WITH_IZB 1
#endif
#ifndef OM_WITH_HYBRID
#define OM_WITH_HYBRID 1
#endif

/* OM_WITH_JOBS: whether the engine carries the code that runs a frame on the host's
 * threads (bands of rows, a method's pass and lent slots: shadow/method.h). 0 on
 * Cortex-M cores (ACLE's __ARM_ARCH_PROFILE 'M': one core), so that a firmware carries
 * none of it; a frame then runs inline whatever parallel-for it is handed, and the
 * frame size query's `jobs` is 0. The same frames either way. */
#ifndef OM_WITH_JOBS
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
#define OM_WITH_JOBS 0
#else
#define OM_WITH_JOBS 1
#endif
#endif

/* OM_FAST_FLOAT: 1 where a double operation is a library routine and a float one is
 * cheaper (32-bit ARM without a double FPU: the Cortex-M4F's is single precision, the
 * M0 and M3 have none; RISC-V without D). ref, asm, rtw, spsm and hybrid then decide in
 * float first, with an error bound, and fall back to double only where the bound
 * leaves the answer open: the same answers and frames (proven at each, and tested).
 * Where double is hardware the bounds only cost, so it is 0; a build may set it
 * either way (make test builds one of its four with 1). */
#ifndef OM_FAST_FLOAT
#if (defined(__arm__) && !(defined(__ARM_FP) && (__ARM_FP & 8))) || \
    (defined(__riscv) && !(defined(__riscv_flen) && __riscv_flen >= 64))
#define OM_FAST_FLOAT 1
#else
#define OM_FAST_FLOAT 0
#endif
#endif

/* OM_SMLOOK_DIRECT: 1 on Cortex-M cores, whose loads take a cycle or two: the
 * shadow-map lookup (shadow/common/smlookup.c) tests each sample as soon as it is
 * located, in place of locating a run of them first. Define it 1 elsewhere to try
 * it. The same terms either way. */
#ifndef OM_SMLOOK_DIRECT
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
#define OM_SMLOOK_DIRECT 1
#else
#define OM_SMLOOK_DIRECT 0
#endif
#endif

/* OM_ALLOW_EXCESS_PRECISION (undefined): the engine refuses to compile where float
 * arithmetic is evaluated in a wider type (FLT_EVAL_METHOD != 0: x87, s390x gcc's
 * standard mode), since its frames would differ in their last bits from every other
 * CPU's (core.h). Defined, it builds anyway, outside that promise: every loop still
 * ends, and the frames may differ. */

#endif
