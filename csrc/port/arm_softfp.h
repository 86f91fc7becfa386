/* arm_softfp.h: correctly rounded soft-double addition for Arm targets
 * without a double-precision FPU (arm_softfp_add.c says why). */
#ifndef PYINS_ARM_SOFTFP_H
#define PYINS_ARM_SOFTFP_H

/* libgcc's double routines take and return doubles in core registers (base
 * AAPCS) whatever the float ABI of their callers. */
#define PYINS_AAPCS __attribute__((pcs("aapcs")))

#ifdef __cplusplus
extern "C" {
#endif

/* a + b, a - b and b - a, correctly rounded (IEEE 754, to nearest, ties to
 * even) where libgcc's __adddf3 is not, else libgcc's own result. */
PYINS_AAPCS double pyins_softfp_dadd(double a, double b);
PYINS_AAPCS double pyins_softfp_dsub(double a, double b);
PYINS_AAPCS double pyins_softfp_drsub(double a, double b);

#ifdef __cplusplus
}
#endif

#endif
