/*
 * manex.h: the "manipulator externals" an RCCL program of the user's manual includes after
 * rccl.h: t6, park, the unit vectors and the rest, all of which rccl.h declares already. Kept
 * so that such programs compile as they were printed. Such a program writes its task as
 *
 *     pumatask() { ... }
 *
 * and no main(): rccx_compat's main() (linked only when the program has none) opens the
 * session on the simulated robot (RCCX_ROBOT, default the Microbo; RCCX_LOG logs every
 * sample), starts the trajectory generator, calls pumatask(), waits until every motion it
 * queued has ended, closes the session, and exits 0 (1 when a motion failed or control ended).
 */
#ifndef RCCX_COMPAT_MANEX_H
#define RCCX_COMPAT_MANEX_H
#include "rccl.h"
#endif
