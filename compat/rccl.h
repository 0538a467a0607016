/*
 * rccl.h: RCCL's C interface, as its user's manual (Hayward and Paul, Purdue TR-EE 83-43) and
 * the thesis (section 2.4) print it, over rccx: transforms with public n, o, a, p vectors,
 * constant, varb, hold and functionally defined transforms, position equations, queued
 * motions, teach, on a simulated robot (the Microbo Ecureuil unless the environment says
 * otherwise). Library rccx_compat (pkg-config rccx-compat); error codes, print_rtc_error() and
 * the real-time names (control, release, how, chg, terminate) are in rtc.h. docs/RCCL.md lists
 * every name of the manual and what it maps to in rccx's C++ API.
 *
 * Units are the 1986 ones: mm for lengths, degrees for angles, mm/s and deg/s for speeds,
 * milliseconds for times. (rccx inside works in m, rad and s; this layer converts.)
 *
 *   b  = gentr_rot("B", 325.0, 150.0, 300.0, xunit, 180.);      constant transform
 *   h  = newtrans("H", hold);  Trsl(h, 0., 0., 10.);           a hold transform
 *   p1 = makeposition("P1", t6, EQ, b, h, TL, t6);              position equation T6 = B H
 *   rccl_open(0, 0); rccl_control();                            session, trajectory generator
 *   setvel(100, 100); move(park); waitfor(park->end);           queue a motion, wait its end
 *   h->p.z += 10.; move(p1);                                    h is read when move() is called
 *   setmod('c'); move(p1); stop(500); waitfor(completed);       Cartesian segment, a dwell
 *   rccl_close(0);
 *
 * Time. rccx simulates the arm in simulated time, which runs only while the program waits:
 * `waitfor(cond)` runs the session one sample at a time until `cond` is true. move() queues a
 * motion and returns at once, as in 1986; nothing moves until the program waits.
 *
 * C dialects. The headers compile without warnings under -std=gnu89, -std=c99 and -std=c11
 * (-Wall -Wextra -pedantic). Old programs that call functions without declaring them compile
 * under gnu89; add -Werror=implicit-function-declaration to have the compiler refuse a call of
 * a name this header does not declare (a misspelt RCCL call) instead of guessing its type.
 * newtrans() is a macro that needs variadic macros (C99, or GNU C89).
 *
 * Environment: RCCX_ROBOT = a shipped robot's name ("microbo", "puma560", ...; `rccx kin
 * robots` lists them) or a robot file (a path ending in .json); default "microbo".
 * RCCX_LOG = FILE writes a CSV row per controlled sample: t, segment (the motion's number,
 * 1, 2, ... in the order of the move() and stop() calls since rccl_open; 0 at rest), commanded
 * and measured joints, the commanded tool pose, after a header line naming the robot; a log
 * that cannot be written makes rccl_close() return RTC_E_LOG. RCCX_DB = the position database
 * teach() reads and writes (default rccx.db in the working directory).
 *
 * Errors. No call aborts the program. A call that fails returns nonzero (or NULL), sets
 * rtc_error and keeps a message (rtc.h); the calls a 1986 program did not check (all but
 * rccl_open, rccl_control and rccl_close) also print that message on stderr. A motion that
 * fails while it runs is printed when it happens. rccl_close() returns an error when anything
 * went wrong in the session (control ended, a motion failed, a move() was refused), so that a
 * program which checks only rccl_close(), as the thesis's do, still exits with an error.
 *
 * Threads: call everything from the program's main thread. Functions of functionally defined
 * transforms run in the sample loop (see newtrans).
 */
#ifndef RCCX_COMPAT_RCCL_H
#define RCCX_COMPAT_RCCL_H

#include <stdio.h> /* FILE, for printr and printv */

#ifdef __cplusplus
extern "C" {
#endif

#ifndef YES
#define YES 1
#endif
#ifndef NO
#define NO 0
#endif

/* --- Vectors ----------------------------------------------------------------------------- */

/** A vector: a position (mm) or a direction (unitless). */
typedef struct vect {
  double x, y, z;
} VECT, *VECT_PTR;

/** The unit vectors along the axes, for rotation axes: gentr_rot(..., xunit, 90.). */
extern const VECT xunit, yunit, zunit;

/* --- Transforms -------------------------------------------------------------------------- */

/** Any C function; newtrans() casts a transform's function to it (K&R functions included). */
typedef void (*RCCL_FN)(void);

/** What a transform is (TRSF.type). */
#define RCCL_CONST 1  /* constant: its value is read when a motion is queued (move) */
#define RCCL_VARB 2   /* variable: read again at every sample while a motion uses it */
#define RCCL_HOLD 3   /* hold: its value is read when move() is called and kept by that motion */
#define RCCL_FUNCT 4  /* functionally defined: fn(t) sets its value at every sample */
#define RCCL_T6 5     /* T6 itself */
#define RCCL_SYSTEM 6 /* computed by rccx (another robot's tool frame, mnp_tool_frame) */

/**
 * A homogeneous transform: the rotation's columns n, o, a (unit vectors, n = o x a) and the
 * position p (mm). A program reads and writes the vectors directly (b->p.z += 10.;). Those
 * made by newtrans() and gentr_*() have a name and a type and may stand in position
 * equations; any other TRSF (a local variable) serves the algebra below.
 */
typedef struct trsf {
  VECT n, o, a, p;
  const char* name; /* as given to newtrans / gentr_* ("" for others) */
  int type;         /* RCCL_CONST, RCCL_VARB, RCCL_HOLD, RCCL_FUNCT, RCCL_T6, RCCL_SYSTEM */
  RCCL_FN fn;       /* RCCL_FUNCT: the function; else NULL */
  long age;         /* the sample in which fn last ran (-1: never) */
  void* rccx;       /* rccx's own: do not touch */
} TRSF, *TRSF_PTR;

/**
 * T6: the pose of the robot's last link in its base frame, the unknown of every position
 * equation. Its n, o, a, p hold the measured T6 (mm) after each sample a wait lets run, and, in
 * the functions of functionally defined transforms, the T6 measured at the sample being
 * computed (one robot's session; in a cell, only after waits: use mnp_ calls there).
 */
extern TRSF_PTR const t6;

/*
 * newtrans(name, type): a new transform, the identity, named `name`. `type` is written as in
 * the manual: const, varb, hold, or the name of a function (a functionally defined transform):
 *
 *     trans = rot(newtrans("TRANS", const), zunit, 90.);
 *     conv  = newtrans("CONV", convfn);
 *
 *     int convfn(t) TRSF_PTR t; { t->p.y = 100. + 0.5 * rtime; return 0; }
 *
 * `const` is a C keyword; newtrans is a macro so that it can still be written there (CONST and
 * RCCL_CONST work too). `type` must be one of those names, not an expression: for a function
 * pointer held in a variable, call rccl_newtrans(name, RCCL_FUNCT, (RCCL_FN)fp).
 *
 * A function is called once per sample (in the sample loop, while a motion that uses the
 * transform is queued or runs) as fn(t), t the transform; it sets t's n, o, a, p (mm), and may
 * read rtime and rccl_sample, and set nextmove (a monitor). It must return quickly and must not
 * call this library (except the algebra below). Its value is not called between samples:
 * move() and update() use the value it last set.
 *
 * NULL on error (a NULL function): rtc_error RTC_E_ARGUMENT. The transform lives until the
 * program ends.
 */
TRSF_PTR rccl_newtrans(const char* name, int type, RCCL_FN fn);
#ifdef __cplusplus
#define RCCL_FN_CAST(f) reinterpret_cast<RCCL_FN>(f)
#define RCCL_FN_NULL nullptr
#else
#define RCCL_FN_CAST(f) ((RCCL_FN)(f))
#define RCCL_FN_NULL ((RCCL_FN)0)
#endif
/* Variadic macros are C99 (and GNU C89): say so to a -pedantic gnu89 build only once, here. */
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wvariadic-macros"
#endif
#define RCCL_NT_2ND(a, b, ...) b
#define RCCL_NT_2ND_(...) RCCL_NT_2ND(__VA_ARGS__)
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
#define RCCL_NT_TYPE_const ~, RCCL_CONST
#define RCCL_NT_TYPE_CONST ~, RCCL_CONST
#define RCCL_NT_TYPE_RCCL_CONST ~, RCCL_CONST
#define RCCL_NT_TYPE_varb ~, RCCL_VARB
#define RCCL_NT_TYPE_VARB ~, RCCL_VARB
#define RCCL_NT_TYPE_RCCL_VARB ~, RCCL_VARB
#define RCCL_NT_TYPE_hold ~, RCCL_HOLD
#define RCCL_NT_TYPE_HOLD ~, RCCL_HOLD
#define RCCL_NT_TYPE_RCCL_HOLD ~, RCCL_HOLD
#define RCCL_NT_FN_const ~, RCCL_FN_NULL
#define RCCL_NT_FN_CONST ~, RCCL_FN_NULL
#define RCCL_NT_FN_RCCL_CONST ~, RCCL_FN_NULL
#define RCCL_NT_FN_varb ~, RCCL_FN_NULL
#define RCCL_NT_FN_VARB ~, RCCL_FN_NULL
#define RCCL_NT_FN_RCCL_VARB ~, RCCL_FN_NULL
#define RCCL_NT_FN_hold ~, RCCL_FN_NULL
#define RCCL_NT_FN_HOLD ~, RCCL_FN_NULL
#define RCCL_NT_FN_RCCL_HOLD ~, RCCL_FN_NULL
#define newtrans(name, type)                                          \
  rccl_newtrans((name), RCCL_NT_2ND_(RCCL_NT_TYPE_##type, RCCL_FUNCT, ~), \
                RCCL_NT_2ND_(RCCL_NT_FN_##type, RCCL_FN_CAST(type), ~))

/**
 * The time in ms since rccl_open() (rtime) and the sample number (rccl_sample, 1, 2, ...). In a
 * transform's function: the time the setpoint being computed is for, and the sample computing
 * it. In the program, after each wait: the time and number of the arm's last reading (the
 * setpoints run a sample or two ahead of it, the arm's pipeline).
 */
extern long rtime;
extern long rccl_sample;

/*
 * Constant transforms made and set in one call (the manual's gentr_ family; the thesis spells
 * them gen_tr_, both work). Translation (x, y, z) in mm, then the rotation:
 *   gentr_trsl  Trans(x, y, z)
 *   gentr_rot   Trans(x, y, z) Rot(axis, angle_deg)          (axis: any nonzero vector)
 *   gentr_eul   Trans(x, y, z) Rot(z, phi) Rot(y, theta) Rot(z, psi)          (Euler, deg)
 *   gentr_rpy   Trans(x, y, z) Rot(z, roll) Rot(y, pitch) Rot(x, yaw)  (roll, pitch, yaw, deg)
 *   gentr_pao   position p, approach vector a, orientation vector o (n = o x a; a and o are
 *               made unit and o orthogonal to a)
 * NULL on error (a zero axis, parallel a and o, a number that is not finite): RTC_E_ARGUMENT.
 */
TRSF_PTR gentr_trsl(const char* name, double x_mm, double y_mm, double z_mm);
TRSF_PTR gentr_rot(const char* name, double x_mm, double y_mm, double z_mm, VECT axis,
                   double angle_deg);
TRSF_PTR gentr_eul(const char* name, double x_mm, double y_mm, double z_mm, double phi_deg,
                   double theta_deg, double psi_deg);
TRSF_PTR gentr_rpy(const char* name, double x_mm, double y_mm, double z_mm, double roll_deg,
                   double pitch_deg, double yaw_deg);
TRSF_PTR gentr_pao(const char* name, double px_mm, double py_mm, double pz_mm, double ax,
                   double ay, double az, double ox, double oy, double oz);
#define gen_tr_trsl gentr_trsl
#define gen_tr_rot gentr_rot
#define gen_tr_eul gentr_eul
#define gen_tr_rpy gentr_rpy
#define gen_tr_pao gentr_pao

/*
 * The algebra of the manual's "basic components" (any TRSF, named or not). Each function puts
 * its result in its first argument and returns it (as strcat does); each has a capitalised
 * form that is a statement, `#define Rot (void) rot`. Results may alias arguments. Positions in
 * mm, angles in degrees. Rotations are exact (no renormalisation); see unit().
 */
TRSF_PTR trmult(TRSF_PTR r, const TRSF* t1, const TRSF* t2);    /* r = t1 t2 */
TRSF_PTR trmultinv(TRSF_PTR r, const TRSF* t1, const TRSF* t2); /* r = t1 t2^-1 */
TRSF_PTR invtrmult(TRSF_PTR r, const TRSF* t1, const TRSF* t2); /* r = t1^-1 t2 */
TRSF_PTR invert(TRSF_PTR r, const TRSF* t);                     /* r = t^-1 */
TRSF_PTR assigntr(TRSF_PTR r, const TRSF* t);                   /* r = t (the value only) */
TRSF_PTR ident(TRSF_PTR r);                                     /* r = I */
TRSF_PTR rot(TRSF_PTR r, VECT axis, double angle_deg);          /* r = Rot(axis, angle) */
TRSF_PTR trsl(TRSF_PTR r, double x_mm, double y_mm, double z_mm); /* r = Trans(x, y, z) */
TRSF_PTR eul(TRSF_PTR r, double phi_deg, double theta_deg, double psi_deg); /* r = Euler zyz */
TRSF_PTR rpy(TRSF_PTR r, double roll_deg, double pitch_deg, double yaw_deg); /* r = RPY */
TRSF_PTR rotr(TRSF_PTR r, VECT axis, double angle_deg); /* r = r Rot(axis, angle): turn in r's frame */
TRSF_PTR trslr(TRSF_PTR r, double x_mm, double y_mm, double z_mm); /* r = r Trans: move in r's frame */
TRSF_PTR takerot(TRSF_PTR r, const TRSF* t);  /* r's rotation = t's (r.p kept) */
TRSF_PTR taketrsl(TRSF_PTR r, const TRSF* t); /* r.p = t.p (r's rotation kept) */
/* The Euler (zyz) and roll-pitch-yaw angles of t (deg), through pointers; returns t. */
const TRSF* trtoeul(const TRSF* t, double* phi_deg, double* theta_deg, double* psi_deg);
const TRSF* trtorpy(const TRSF* t, double* roll_deg, double* pitch_deg, double* yaw_deg);
#define Trmult (void) trmult
#define Trmultinv (void) trmultinv
#define Invtrmult (void) invtrmult
#define Invert (void) invert
#define Assigntr (void) assigntr
#define Ident (void) ident
#define Rot (void) rot
#define Trsl (void) trsl
#define Eul (void) eul
#define Rpy (void) rpy
#define Rotr (void) rotr
#define Trslr (void) trslr
#define Takerot (void) takerot
#define Taketrsl (void) taketrsl
#define Trtoeul (void) trtoeul
#define Trtorpy (void) trtorpy

VECT_PTR vecmult(VECT_PTR r, const TRSF* t, const VECT* v);   /* r = t v (a point: R v + p) */
VECT_PTR rotvec(VECT_PTR r, const TRSF* t, const VECT* v);    /* r = R v (a direction) */
VECT_PTR vecadd(VECT_PTR r, const VECT* u, const VECT* v);    /* r = u + v */
VECT_PTR vecsub(VECT_PTR r, const VECT* u, const VECT* v);    /* r = u - v */
VECT_PTR vecscale(VECT_PTR r, const VECT* v, double s);       /* r = s v */
VECT_PTR cross(VECT_PTR r, const VECT* u, const VECT* v);     /* r = u x v */
VECT_PTR unit(VECT_PTR r, const VECT* v);                     /* r = v / |v| (zero stays zero) */
double dot(const VECT* u, const VECT* v);                     /* u . v */
double norm(const VECT* v);                                   /* |v| */
#define Vecmult (void) vecmult
#define Rotvec (void) rotvec
#define Vecadd (void) vecadd
#define Vecsub (void) vecsub
#define Vecscale (void) vecscale
#define Cross (void) cross
#define Unit (void) unit

/*
 * Printing, on `fp` (stdout, stderr, a file): printr the name and the 3 x 4 matrix (rows of
 * n o a p, p in mm), printv a vector. printtr is another name for printr. They return their
 * first argument.
 */
const TRSF* printr(const TRSF* t, FILE* fp);
const VECT* printv(const VECT* v, FILE* fp);
#define printtr printr
#define Printr (void) printr
#define Printv (void) printv

/* --- Positions ---------------------------------------------------------------------------- */

/** A position equation made by makeposition (or park). Read-only for the program. */
typedef struct rccl_position {
  /**
   * True (1) when no motion to this position is queued or running: every motion move()
   * queued to it has ended (or failed, or was cancelled). move() sets it to 0 at once; it
   * becomes 1 again in the sample the last such motion ends, so `waitfor(p->end)` waits for
   * the arm to get there. Updated by every call of this library and every waited sample.
   */
  int end;
  /** The name given to makeposition ("park" for park). */
  const char* name;
  /**
   * How the last motion to it that ended ended: 0 normally (at the goal), RCCL_NEXTMOVE when
   * nextmove ended it before the goal, RTC_E_MOTION when it failed or was cancelled.
   */
  int code;
} POS, *POS_PTR;

#define RCCL_NEXTMOVE 1 /* POS.code: ended early by nextmove */

/** The separators of makeposition's list: left side, EQ, right side, TL, tool. */
extern TRSF_PTR const rccl_EQ;
extern TRSF_PTR const rccl_TL;
#define EQ rccl_EQ
#define TL rccl_TL

/**
 * The position equation `name`: the transforms of the left side (T6 among them), EQ, those
 * of the right side, TL, and the tool transform (one of the left side's at or after t6; t6
 * itself for no tool):
 *
 *     makeposition("P1", t6, EQ, b, TL, t6)                      T6 = B
 *     makeposition("P", z, t6, tool, EQ, conv, obj, TL, tool)    Z T6 TOOL = CONV OBJ
 *
 * Every argument after the name is a TRSF_PTR made by newtrans or gentr_* (or t6). The list
 * ends after the transform that follows TL; it must contain EQ then TL (a NULL, an unknown
 * pointer or TL before EQ stops it). NULL on error, with rtc_error = RTC_E_EQUATION (or
 * RTC_E_ARGUMENT) and a message saying what is wrong. The position lives until the program
 * ends. Transforms are read when a motion to it is queued (const, hold) or at each sample
 * (varb, functional), not here.
 */
POS_PTR makeposition(const char* name, ...);

/**
 * The robot's park position (its ready pose, given in joints). Usable once rccl_open() has
 * chosen the robot.
 */
extern POS_PTR const park;

/* --- The session ---------------------------------------------------------------------------- */

/**
 * Opens an RCCL session (rtc_open): a simulated robot and its RTC session, in simulated time.
 * `robot`: a robot name or file; NULL (or 0) for RCCX_ROBOT, else "microbo". `period_ms`:
 * the sample period in ms (0.25 .. 56); 0 for the robot's usual one (28 ms for the Microbo,
 * 10 ms for the others). Returns 0, or an error code (RTC_E_SEQUENCE, RTC_E_ROBOT,
 * RTC_E_OPEN, RTC_E_ARGUMENT) also in rtc_error.
 */
int rccl_open(const char* robot, double period_ms);

/**
 * Starts the trajectory generator (rtc_control with RCCL's setpoint), at rest where the arm
 * stands. Returns 0, or RTC_E_SEQUENCE (not open, or started already).
 */
int rccl_control(void);

/**
 * Ends the session (rtc_release and rtc_close): motions still queued are dropped and the arm
 * holds where it is; `power_off` nonzero also turns arm power off. Returns 0, or the first
 * of these that applies: RTC_E_TERMINATED when control had ended by itself (a limit, a
 * fault, Ctrl-C); RTC_E_MOTION when a motion failed or was cancelled during the session; the
 * code of the first move() that was refused during the session (RTC_E_UNREACHABLE, ...);
 * RTC_E_LOG when the RCCX_LOG file could not be written whole (a full disk, an I/O error: the
 * log is lost, the file left as it was); RTC_E_SEQUENCE when no session is open. The session
 * is closed in every case; rccl_open() may follow.
 */
int rccl_close(int power_off);

/* --- Motion settings (for the motions queued after the call) ------------------------------ */

/**
 * setvel: the tool's translation speed (mm/s) and rotation speed (deg/s) along a segment,
 * both > 0. Default 100 mm/s, 100 deg/s. Returns 0 or RTC_E_ARGUMENT.
 */
int setvel(double mm_per_s, double deg_per_s);

/**
 * setmod: 'j' joint mode (joints interpolated between the end points; the default) or 'c'
 * Cartesian mode (the tool frame on a straight line). Returns 0 or RTC_E_ARGUMENT.
 */
int setmod(int mode);

/**
 * settime: the transition time `transition_ms` (ms, > 0: the length of the blend into the
 * next segment, centred on the via point; default 200 ms) and the segment time `segment_ms`
 * (ms; > 0: each segment lasts that long, 0: from the speeds of setvel, the default). The
 * thesis (2.4.2) names both times but not their order: the transition time comes first here.
 * Times are lengthened when a joint would exceed its speed or acceleration bound (the
 * generator slows down rather than fail). Returns 0 or RTC_E_ARGUMENT.
 */
int settime(double transition_ms, double segment_ms);

/**
 * setconf: the arm configuration the next joint-mode motions reach their goals in, as letters
 * or words: for the PUMA l/r (lefty, righty: the shoulder), u/d (up, down: the elbow), n/f
 * (noflip, flip: the wrist), e.g. "lun", "r", "righty down flip"; for the Microbo n/f. Letters
 * not given keep the arm's present ones; "" goes back to "stay in the present configuration"
 * (the default). A Cartesian motion cannot change configuration: move() refuses, at the call,
 * a Cartesian goal the present configuration does not reach (RTC_E_UNREACHABLE), saying which
 * configuration does. Returns 0, or RTC_E_ARGUMENT for a letter the robot does not have.
 */
int setconf(const char* configuration);

/* --- Motions ----------------------------------------------------------------------------- */

/**
 * Queues a motion to `p` with the present settings and returns at once; the trajectory
 * generator joins queued motions with transitions. Const and hold transforms of the equation
 * are read now (a later change reaches the next move), varb and functional ones at every
 * sample. Motions are numbered 1, 2, ... in the order of the move() and stop() calls (the
 * `segment` column of the RCCX_LOG file). Returns 0, or an error code: RTC_E_UNREACHABLE (a
 * goal that no configuration reaches within the joint limits, a Cartesian goal the present
 * configuration does not reach, a full queue), RTC_E_EQUATION (a const or hold transform set
 * to a value that is not a rigid transform), RTC_E_SEQUENCE (before rccl_control),
 * RTC_E_TERMINATED (control has ended), RTC_E_ARGUMENT (a null or unknown position). Nothing is
 * queued on error.
 */
int move(POS_PTR p);

/**
 * stop: the motion queued before comes to rest, the arm stays there (tracking a moving goal)
 * for `ms` milliseconds (>= 0; rounded up to whole samples, at least 3: docs/RCCL.md), then the
 * next starts from rest. Queued like move(). Returns 0 or an error code as move().
 */
int stop(double ms);

/**
 * distance: displaces the goal of the next move() in the tool frame of its equation: `what`
 * lists the displacements, each followed by its value among the arguments (double):
 * "dx", "dy", "dz" in mm, "rx", "ry", "rz" in deg (a rotation about that tool axis, applied
 * after the translations), e.g. distance("dz", -30.) then move(p): 30 mm short of p along the
 * tool's z; distance("dx dz", 10., 5.). Several calls add up; the next move() takes them.
 * Returns 0 or RTC_E_ARGUMENT (an unknown word; nothing is changed).
 */
int distance(const char* what, ...);

/**
 * True (1) when every motion queued so far has ended (the queue is empty and the arm at
 * rest): `waitfor(completed)`. Updated like POS.end.
 */
extern int completed;

/**
 * nextmove: set it to YES (from the program, or from a transform's function in the sample
 * loop: a monitor) to end the motion running now: the arm stops smoothly where it is (every
 * joint within its bounds), that motion ends (its POS.code becomes RCCL_NEXTMOVE) and the next
 * queued motion starts from there. The library sets it back to NO when it has acted on it
 * (at once when no motion runs).
 */
extern volatile int nextmove;

/**
 * Lets one sample of the session run (in simulated time; in real time, waits one period),
 * then updates every POS.end and `completed`, and prints the motions that failed. Returns 0,
 * or nonzero when waiting cannot make anything happen: no control session
 * (RTC_E_SEQUENCE), or control has ended (RTC_E_TERMINATED; printed once).
 */
int rccl_wait_sample(void);

/**
 * waitfor(cond): waits, sample by sample, until the int expression `cond` is true (nonzero):
 * waitfor(p->end), waitfor(completed). `cond` is evaluated before each sample. Returns early
 * when rccl_wait_sample() says waiting is useless (see there).
 */
#define waitfor(cond)                     \
  do {                                    \
    while (!(cond)) {                     \
      if (rccl_wait_sample() != 0) break; \
    }                                     \
  } while (0)

/* --- Solving for a transform: update and teach ---------------------------------------------- */

/**
 * update(trans, pos): sets `trans` (one of pos's transforms, not t6) to the value that makes
 * the equation of `pos` hold with T6 where the arm is now (measured), the other transforms at
 * their present values. For a hold transform the next move() takes it. Returns trans, or NULL
 * (RTC_E_ARGUMENT: trans is not in pos, or is t6; RTC_E_SEQUENCE: no session).
 */
TRSF_PTR update(TRSF_PTR trans, POS_PTR pos);

/**
 * teach(trans, pos): as the manual's teach mode. `trans` is first looked up by its name in the
 * position database (RCCX_DB, default rccx.db), for this robot: when found, trans takes that
 * value and teach returns YES at once. Otherwise the teach loop runs on the terminal
 * ("teach mode V1.0, transform TRANS, position POS"; `?` lists the commands: zero gravity, a
 * joint to a value, jogging, ...); `e` records T6 there, solves trans as update() does,
 * stores it in the database under its name and returns YES. The loop ending otherwise (the
 * input runs out, Ctrl-C, control ends) returns NO and leaves trans as it was. Waits for the
 * queued motions to end first.
 */
int teach(TRSF_PTR trans, POS_PTR pos);

/* --- Force: guards and compliance (a robot with a wrist force sensor) ---------------------- */
/*
 * What the Microbo port had to leave out (thesis 4.4.2), on a robot whose simulated plant has
 * a wrist force/torque sensor (the MuJoCo plant: "plant": "mujoco" in its robot file; others
 * refuse these motions at move(), with a message that says so). Axes are those of the motion's tool
 * frame (T6 TOOL, TOOL from makeposition's TL): fx fy fz in N, tx ty tz in N m, and a force is
 * the one the tool exerts on what it touches (pressing the tool's z onto a table: fz > 0).
 * Like setvel, each call applies to the motions queued after it.
 */

/**
 * comply: the axes named yield, each holding the force that follows it among the arguments
 * (double, N or N m): comply("fz", 5.) presses with 5 N along the tool's z; comply("fx fy",
 * 0., 0.) lets a push move the tool in x and y. Returns 0 or RTC_E_ARGUMENT (nothing changed).
 */
int comply(const char* what, ...);
/** lock: the axes named follow the path again (lock("fz"), lock("all")). */
int lock(const char* what);
/**
 * limit: the motions queued from now on end, as nextmove ends them (smoothly, where the arm
 * is; POS.code RCCL_ONF), when the tool exerts the force that follows the axis among the
 * arguments: limit("fz", 8.); limit("f", 10.): the force's magnitude. limit("off") removes it.
 * One axis at a time. Returns 0 or RTC_E_ARGUMENT.
 */
int limit(const char* what, ...);
#define RCCL_ONF 2 /* POS.code: ended on force, by a limit() guard */
/**
 * setload: the tool's mass (kg) and centre of mass (mm, in T6) for gravity compensation of
 * the wrist sensor's readings. Returns 0, RTC_E_ARGUMENT or RTC_E_SEQUENCE (no session).
 */
int setload(double kg, double x, double y, double z);
/**
 * getcontact: YES when the last motion to pos that ended stopped on force; `at` (may be 0) gets
 * the tool frame where the contact began (mm). NO otherwise.
 */
int getcontact(POS_PTR pos, TRSF_PTR at);
/**
 * updatecontact: update() with T6 where the last motion to pos touched (the world model learns
 * where the surface is): sets trans and returns it, or 0 (no contact: RTC_E_SEQUENCE).
 */
TRSF_PTR updatecontact(TRSF_PTR trans, POS_PTR pos);

/* --- Several robots: a workcell (Multi-RCCL style) ------------------------------------------- */
/*
 * A program may drive all the robots of a cell file (cells/ *.json: robots placed in a world
 * frame) instead of one: rccl_cell_open() instead of rccl_open(), a MANIP handle per robot
 * (Multi-RCCL's rcclCreate), the mnp_ calls with the handle first where the one-robot calls have
 * none, and rcclStart / rcclRelease for rccl_control / rccl_close. Transforms, makeposition,
 * POS.end and waitfor() are shared: waitfor() lets one tick of the cell's clock run. The
 * one-robot calls (move, setvel, ...) are refused while a cell is open (RTC_E_SEQUENCE).
 *
 *   rccl_cell_open("cells/cvarl.json");
 *   MANIP *puma = rcclCreate("puma", 0), *mbo = rcclCreate("microbo", 0);
 *   rcclStart();
 *   p = makeposition("P", t6, mnp_tool(puma), EQ, mnp_base_inv(puma), goal, TL, mnp_tool(puma));
 *   mnp_move(puma, p);  a = mnp_last_motion(puma);
 *   mnp_after(mbo, puma, a, RCCL_END);  mnp_move(mbo, q);   the Microbo starts when P is reached
 *   waitfor(mnp_completed(mbo));
 *   rcclRelease(0);
 */

/** A robot of the open cell (opaque). */
typedef struct rccl_manip MANIP;

/** The events of another robot's motion that mnp_after() waits for. */
#define RCCL_START 1
#define RCCL_END 2

/**
 * Opens the cell described by `cell_file` (NULL: the environment variable RCCX_CELL, else the
 * shipped cells/cvarl.json: under $RCCX_DATA_DIR, the source tree, the installed share/rccx),
 * its robots simulated in simulated time. Returns 0, or an error
 * code (RTC_E_SEQUENCE: a session or cell is open; RTC_E_ROBOT: a bad cell file, the message
 * says where).
 */
int rccl_cell_open(const char* cell_file);

/*
 * Across processes (docs/NETWORK.md, "The C interface across processes"): the same calls drive
 * the robots that `rccx serve` processes run, in real time, when the environment has
 * RCCX_CELL_REMOTE=1 (rccl_cell_open then joins them: a program does not change) or the program
 * calls rccl_cell_open_remote. The DDS domain is `domain` (-1: $RCCX_DOMAIN, else 0), the
 * network interface $RCCX_DDS_INTERFACE ("lo" on one machine), the time after which a silent
 * serve process counts as lost $RCCX_DETECTION_MS (default 20); with $RCCX_SECURE_DIR (the
 * directory of `rccx certs init`) the program joins with DDS Security as the participant
 * $RCCX_SECURE_IDENTITY (default "program"). Every robot of the cell file
 * must be served (RTC_E_OPEN after 10 s otherwise, naming the robot and the serve command).
 * What cannot cross processes is refused with its reason: rccl_together (RTC_E_NOT_YET), a
 * position with a C function's transform (RTC_E_UNREACHABLE at mnp_move). mnp_tool_frame's
 * transform is sent by name ("frame:<robot>"); its TRSF's values stay those of the identity
 * in the program. waitfor() waits about 1 ms a tick; rtime and rccl_sample are the first
 * robot's (by name) serve process's.
 */
int rccl_cell_open_remote(const char* cell_file, int domain);

/**
 * The robot `name` of the open cell (Multi-RCCL's rcclCreate; `flags` reserved, pass 0). The
 * same handle for the same name. NULL on error (RTC_E_SEQUENCE without a cell, RTC_E_ROBOT
 * for a name the cell does not have: the message lists them).
 */
MANIP* rcclCreate(const char* name, int flags);

/** Starts every robot's trajectory generator (rccl_control for the cell). 0 or an error. */
int rcclStart(void);

/**
 * Closes the cell (rccl_close for every robot). Returns 0, or the first error of the session
 * as rccl_close() does (RTC_E_TERMINATED, RTC_E_MOTION, a refused mnp_move's code). Handles
 * are invalid afterwards.
 */
int rcclRelease(int power_off);

/** setvel, setmod, settime for one robot of the cell (units as there). 0 or RTC_E_ARGUMENT. */
int mnp_setvel(MANIP* m, double mm_per_s, double deg_per_s);
int mnp_setmod(MANIP* m, int mode);
int mnp_settime(MANIP* m, double transition_ms, double segment_ms);

/**
 * move() for one robot of the cell: queues a motion to `p` and returns 0 (or an error code,
 * as move()). Its number, for mnp_after and the mnp_ tests, is mnp_last_motion(m) afterwards.
 * It waits for the conditions set by mnp_after / rccl_together since the robot's last
 * mnp_move, which it takes.
 */
int mnp_move(MANIP* m, POS_PTR p);
/** The number of the robot's last motion queued (1, 2, ...; 0 before the first). */
int mnp_last_motion(const MANIP* m);

/**
 * The next mnp_move of `m` starts only once motion `motion` of robot `other` has started
 * (RCCL_START) or ended (RCCL_END); at most 4 per motion. If that motion fails, or `other`'s
 * control ends first, the waiting motion is cancelled with the reason (printed, like a
 * failure). Returns 0, or RTC_E_ARGUMENT (a null handle, a motion never queued, a bad event).
 */
int mnp_after(MANIP* m, MANIP* other, int motion, int event);
/*
 * The cell's objects (names, separated by commas or spaces: "board,xy_stage") that the tool of
 * m's next mnp_move may touch: the collision check lets the tool's capsules come within the
 * margin of them and no others ("" for none, as every motion starts). Returns 0, or
 * RTC_E_ARGUMENT naming the cell's objects for an unknown name.
 */
int mnp_touch(MANIP* m, const char* objects);

/**
 * A joint start: the next mnp_move of each listed robot (a NULL-terminated list of MANIP*)
 * starts in the same sample as the others'; with `end_together` nonzero they also come to rest
 * in the same sample, the faster ones slowed to the slowest. 0 or RTC_E_ARGUMENT.
 */
int rccl_together(int end_together, ...);

/** 1 once motion `motion` of `m` has started / ended (failed or cancelled included). */
int mnp_started(const MANIP* m, int motion);
int mnp_ended(const MANIP* m, int motion);
/** 1 when every motion queued for `m` has ended: waitfor(mnp_completed(m)). */
int mnp_completed(const MANIP* m);

/** The robot's park position (its ready pose, in joints). */
POS_PTR mnp_park(MANIP* m);
/** The robot's tool transform from the cell file (T6 to the tool point; identity without). */
TRSF_PTR mnp_tool(MANIP* m);
/** BASE^-1 of the robot (constant): makeposition(..., EQ, mnp_base_inv(m), world_goal, ...). */
TRSF_PTR mnp_base_inv(MANIP* m);
/**
 * A functional transform: robot `leader`'s commanded tool frame in the world at each sample,
 * so that another robot follows what `leader` holds (EQ, mnp_base_inv(m), mnp_tool_frame(l),
 * grasp).
 */
TRSF_PTR mnp_tool_frame(MANIP* leader);

#ifdef __cplusplus
}
#endif

#endif /* RCCX_COMPAT_RCCL_H */
