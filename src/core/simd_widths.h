/* Instantiates the kernel template RR_TEMPLATE (a header path) once per vector
 * width, as llvmpipe's templates are: W = 1 (plain code, any machine) and, where x86
 * intrinsics may be used, W = 8 inside AVX2-target functions. The template reads W,
 * TARGET and the width's vector types VF, VI and operations VF_(op), VI_(op) of
 * core/simd.h; this file defines and clears them around each inclusion. */
#define VF RR_VF(W)
#define VI RR_VI(W)
#define VF_(op) RR_VF_OP(W, op)
#define VI_(op) RR_VI_OP(W, op)

#define W 1
#define TARGET
#include RR_TEMPLATE
#undef W
#undef TARGET

#ifdef RR_SIMD_X86
#define W 8
#define TARGET RR_TARGET_AVX2
#include RR_TEMPLATE
#undef W
#undef TARGET
#endif

#undef VF
#undef VI
#undef VF_
#undef VI_
#undef RR_TEMPLATE
