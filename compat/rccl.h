/*
 * rccl.h: RCCL's 1986 C interface (thesis section 2.4) over rccx, so that the programs of the
 * thesis compile as C and run: on a simulated robot, the Microbo Ecureuil unless the
 * environment says otherwise. Library rccx_compat; error codes and print_rtc_error() are in
 * rtc.h.
 *
 * Units are the 1986 ones: mm for lengths, degrees for angles, mm/s and deg/s for speeds,
 * milliseconds for times. (rccx inside works in m, rad and s; this layer converts.)
 *
 *   b  = gen_tr_rot("B", 325.0, 150.0, 300.0, xunit, 180.);    constant transform
 *   p1 = makeposition("P1", t6, EQ, b, TL, t6);                 position equation T6 = B
 *   rccl_open(0, 0); rccl_control();                            session, trajectory generator
 *   setvel(100, 100); move(park); waitfor(park->end);           queue a motion, wait its end
 *   setmod('c'); move(p1); move(p2); waitfor(completed);        Cartesian segments, joined
 *   rccl_close(0);
 *
 * Time. rccx simulates the arm in simulated time, which runs only while the program waits:
 * `waitfor(cond)` runs the session one sample at a time until `cond` is true. move() queues a
 * motion and returns at once, as in 1986; nothing moves until the program waits.
 *
 * Environment: RCCX_ROBOT = a shipped robot's name ("microbo", "puma560", ...; `rccx kin
 * robots` lists them) or a robot file (a path ending in .json); default "microbo".
 * RCCX_LOG = FILE writes a CSV row per controlled sample: t, segment (the motion's number,
 * 1, 2, ... in the order of the move() calls since rccl_open; 0 at rest), commanded and
 * measured joints, the commanded tool pose.
 *
 * Errors. No call aborts the program. A call that fails returns nonzero (or NULL), sets
 * rtc_error and keeps a message (rtc.h); the calls a 1986 program did not check (all but
 * rccl_open, rccl_control and rccl_close) also print that message on stderr. A motion that
 * fails while it runs is printed when it happens. rccl_close() returns an error when anything
 * went wrong in the session (control ended, a motion failed, a move() was refused), so that a
 * program which checks only rccl_close(), as the thesis's do, still exits with an error.
 *
 * One thread: call everything from the program's main thread.
 */
#ifndef RCCX_COMPAT_RCCL_H
#define RCCX_COMPAT_RCCL_H

#ifdef __cplusplus
extern "C" {
#endif

/* --- Transforms ------------------------------------------------------------------------- */

/** A transform of a position equation (opaque; made by gen_tr_rot, or t6). */
typedef struct rccl_trsf* TRSF_PTR;

/** A vector: a rotation axis (any length but zero; only its direction counts). */
typedef struct vect {
  double x, y, z;
} VECT;

/** The unit vectors along the base frame's axes, for gen_tr_rot's axis. */
extern const VECT xunit, yunit, zunit;

/**
 * T6: the pose of the robot's last link in its base frame, the unknown of every position
 * equation (RCCL's t6).
 */
extern TRSF_PTR const t6;

/**
 * A constant transform named `name`: a translation of (x_mm, y_mm, z_mm) (mm) and a rotation
 * of `angle_deg` (degrees, right-handed) about `axis`, Trans(x, y, z) Rot(axis, angle).
 * NULL on error (a zero or non-finite axis, a non-finite number): rtc_error is
 * RTC_E_ARGUMENT. The transform lives until the program ends.
 */
TRSF_PTR gen_tr_rot(const char* name, double x_mm, double y_mm, double z_mm, VECT axis,
                    double angle_deg);

/* --- Positions ---------------------------------------------------------------------------- */

/** A position equation made by makeposition (or park). */
typedef struct rccl_position {
  /**
   * True (1) when no motion to this position is queued or running: every motion move()
   * queued to it has ended (or failed, or was cancelled). move() sets it to 0 at once; it
   * becomes 1 again in the sample the last such motion ends, so `waitfor(p->end)` waits for
   * the arm to get there. Updated by every call of this library and every waited sample;
   * read-only for the program.
   */
  int end;
  /** The name given to makeposition ("park" for park). */
  const char* name;
} POS, *POS_PTR;

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
 *     makeposition("P1", t6, EQ, b, TL, t6)          T6 = B
 *     makeposition("P", z, t6, tool, EQ, conv, obj, TL, tool)   Z T6 TOOL = CONV OBJ
 *
 * Every argument after the name is a TRSF_PTR. The list ends after the transform that
 * follows TL; it must contain EQ then TL (a NULL, an unknown pointer or TL before EQ stops
 * it). NULL on error, with rtc_error = RTC_E_EQUATION (or RTC_E_ARGUMENT) and a message
 * saying what is wrong. The position lives until the program ends.
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
 * RTC_E_SEQUENCE when no session is open. The session is closed in every case; rccl_open()
 * may follow.
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
 * settime: the transition time `transition_ms` (ms, > 0: the length of the quartic blend
 * into the next segment, centred on the via point; default 200 ms) and the segment time
 * `segment_ms` (ms; > 0: each segment lasts that long, 0: from the speeds of setvel, the
 * default). The thesis (2.4.2) names both times but not their order: the transition time
 * comes first here. Times are lengthened when a joint would exceed its speed or acceleration
 * bound. Returns 0 or RTC_E_ARGUMENT.
 */
int settime(double transition_ms, double segment_ms);

/* --- Motions ----------------------------------------------------------------------------- */

/**
 * Queues a motion to `p` with the present settings and returns at once; the trajectory
 * generator joins queued motions with transitions. Motions are numbered 1, 2, ... in the
 * order of the calls (the `segment` column of the RCCX_LOG file). Returns 0, or an error
 * code: RTC_E_UNREACHABLE (a fixed goal that no configuration reaches within the joint
 * limits, a full queue), RTC_E_SEQUENCE (before rccl_control), RTC_E_TERMINATED (control
 * has ended), RTC_E_ARGUMENT (a null or unknown position). Nothing is queued on error.
 */
int move(POS_PTR p);

/**
 * True (1) when every motion queued so far has ended (the queue is empty and the arm at
 * rest): `waitfor(completed)`. Updated like POS.end.
 */
extern int completed;

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
 * shipped cells/cvarl.json), its robots simulated in simulated time. Returns 0, or an error
 * code (RTC_E_SEQUENCE: a session or cell is open; RTC_E_ROBOT: a bad cell file, the message
 * says where).
 */
int rccl_cell_open(const char* cell_file);

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
