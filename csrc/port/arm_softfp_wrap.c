/* arm_softfp_wrap.c: the compiler's calls to libgcc's double addition and
 * subtraction routed to arm_softfp_add.c, linked with
 * -Wl,--wrap=__aeabi_dadd,--wrap=__aeabi_dsub,--wrap=__aeabi_drsub (the
 * pyins_core target's link options on the M4F). A separate object from the
 * routines so that an image with wrappers of its own (ops_main.c, which
 * counts the calls) links the routines without these. */
#include "arm_softfp.h"

PYINS_AAPCS double __wrap___aeabi_dadd(double a, double b);
PYINS_AAPCS double __wrap___aeabi_dsub(double a, double b);
PYINS_AAPCS double __wrap___aeabi_drsub(double a, double b);

PYINS_AAPCS double __wrap___aeabi_dadd(double a, double b) { return pyins_softfp_dadd(a, b); }
PYINS_AAPCS double __wrap___aeabi_dsub(double a, double b) { return pyins_softfp_dsub(a, b); }
PYINS_AAPCS double __wrap___aeabi_drsub(double a, double b) { return pyins_softfp_drsub(a, b); }
