/*
 * rtc.h: the 1986 RTC names a C program of the thesis uses (section 2.3): the error variable
 * `rtc_error` and `print_rtc_error()`. Part of rccx's C compatibility layer (library
 * rccx_compat, see rccl.h for the motion calls); the real-time layer underneath is rccx::rtc.
 *
 * Every call of rccl.h that fails sets `rtc_error` to one of the codes below and keeps a
 * message saying what went wrong and what to do (rtc_error_message()). Codes are never reset
 * by a call that succeeds: test the call's result, then read `rtc_error`.
 *
 * The planning level is one thread: call these functions from one thread only.
 */
#ifndef RCCX_COMPAT_RTC_H
#define RCCX_COMPAT_RTC_H

#ifdef __cplusplus
extern "C" {
#endif

/* The values of rtc_error. */
#define RTC_OK 0            /* no error */
#define RTC_E_SEQUENCE 1    /* a call out of order: move() before rccl_control(), two opens */
#define RTC_E_ROBOT 2       /* no such robot (RCCX_ROBOT), or it cannot be simulated */
#define RTC_E_OPEN 3        /* the session cannot open: a bad period, RCCX_LOG not writable */
#define RTC_E_ARGUMENT 4    /* a bad argument: a null or unknown pointer, a speed <= 0, ... */
#define RTC_E_EQUATION 5    /* a malformed position equation (makeposition) */
#define RTC_E_UNREACHABLE 6 /* a motion not queued: goal out of reach or limits, queue full */
#define RTC_E_MOTION 7      /* a queued motion failed (or was cancelled) while running */
#define RTC_E_TERMINATED 8  /* control ended by itself: a limit, a fault, Ctrl-C */
#define RTC_E_INTERNAL 9    /* an unexpected failure inside rccx (the message says which) */
#define RTC_E_NOT_YET 10    /* a call rccx declares but does not do yet */
#define RTC_E_LOG 11        /* the RCCX_LOG file is lost: a write failed (full disk, I/O error) \
                               or rows were dropped; the file is left as it was */

/** The code of the last error (RTC_OK until one happens). */
extern int rtc_error;

/**
 * Prints the meaning of error `code` on stdout, as the 1986 RTC did; when `code` is the
 * present rtc_error, also the message of that error (what failed, why, what to do).
 * `flags`: reserved, pass 0 (the thesis's programs all do).
 */
void print_rtc_error(int code, int flags);

/** The message of the last error ("" when there was none). Valid until the next call. */
const char* rtc_error_message(void);

/** The name of an error code ("RTC_E_EQUATION"), or "unknown". */
const char* rtc_error_name(int code);

/* ------------------------------------------------------------------------------------------
 * The real-time level: the RTC of the 1983 manual (Hayward, TR-EE 83-42: control(fn1, fn2),
 * release(msg), how, chg, terminate, mess) and of the thesis (2.3 and 4.5.4.1: rtc_open,
 * rtc_control, rtc_release, rtc_close, terminate, rtc_message, user_hangup,
 * print_terminate_code), one layer over rccx::rtc::Session, on a simulated robot.
 *
 * The robot: RCCX_ROBOT names a shipped robot ("microbo", "puma560", ...) or a robot file
 * (a path, or a name ending in .json); default microbo, at its usual period (28 ms; 10 ms for
 * the others). RCCX_LOG=FILE writes a CSV row per controlled sample, after a header line that
 * names the robot (README.md); rtc_close() returns RTC_E_LOG when it could not be written.
 *
 * Time: in REAL time by default; RCCX_CLOCK=simulated selects simulated time (deterministic,
 * faster than real time), where time passes only inside rtc_wait() and
 * rtc_wait_terminated(). RCCX_CLOCK=real is the default said out loud. A real-time program may
 * let time pass any way it likes (sleep(), a busy loop on terminate, rtc_wait()).
 *
 * The cycle, each sample while control is active (1983: onintr1, pack, onintr2):
 *   1. the library reads the arm into `how`;
 *   2. fn1 runs; its commands in `chg` are checked and sent at once;
 *   3. fn2 runs; its commands go out with the next sample.
 * After each function the library takes `chg` (converting mm to m), then clears its one-shot
 * commands (motion[j].set, hand, power, zerog, outset, outclr), keeps valir, vel and checking,
 * and reads `terminate` and `rtc_message`. Each function must return within the period.
 *
 * Threads. The control functions run on the control task's thread, the program on its own:
 *   - touch `how` and `chg` only inside fn1 / fn2 (rtc_open(), control() and rtc_control()
 *     fill `how` once before control starts, and after control has ended it holds the last
 *     sample, so the program may read it then);
 *   - `terminate` may be set by a control function, or read by the program after rtc_wait(),
 *     rtc_wait_terminated(), release() or rtc_release() returned: all race-free. A program
 *     may also busy-wait, `while (!terminate) ;` (real time only: in simulated time nothing
 *     moves while it spins): terminate is volatile and the library writes it as one atomic
 *     store, so the loop ends, but ThreadSanitizer reports it as a data race; the race-free
 *     poll is `while (rtc_wait(10.) == RTC_OK) ;`.
 *
 * An RTC session and an RCCL session (rccl_open, rccl_cell_open) cannot be open together:
 * each refuses with RTC_E_SEQUENCE. No call aborts: a failure returns its code, sets
 * rtc_error and keeps the message (rtc_error_message(), print_rtc_error()).
 *
 * Old programs: compile with -Werror=implicit-function-declaration (a misspelt or undeclared
 * call is then an error, not a silent int function), and K&R control functions with implicit
 * int and no return value with -std=gnu89 -Wno-implicit-int -Wno-return-type
 * (examples/c/rtc_sine.c). This header compiles without warnings under gnu89, c99 and c11
 * with -Wall -Wextra -pedantic.
 *
 * C++ programs: the global variables below are declared only when RCCX_RTC_GLOBALS is defined
 * before this header (rccx's own files keep their local names such as `how`).
 */

#define RTC_MAX_JOINTS 8 /* joints of how and chg (the robot uses how.dof of them) */

/* chg.i.motion[j].set: what to do with joint j this sample (thesis 4.5.4.1). */
#define RTC_NOCMD 0   /* nothing: the joint goes on as it was */
#define RTC_POS 1     /* go to valir at vel (0: a quarter of the joint's top speed) */
#define RTC_POSVEL 2  /* be at valir one sample period from now */
#define RTC_STOPCAL 3 /* stop and seek the calibration position (joint-level calibration) */
#define NOCMD RTC_NOCMD
#define POSVEL RTC_POSVEL
#define STOPCAL RTC_STOPCAL
/* POS is also rccl.h's position type: the thesis's spelling `set = POS` is defined here only
   when rccl.h has not been included (nor RTC_NO_POS defined), and only in C. A program that
   uses both headers includes rccl.h first and writes RTC_POS. */
#if !defined(__cplusplus) && !defined(RCCX_COMPAT_RCCL_H) && !defined(RTC_NO_POS)
#define POS RTC_POS
#endif

/* chg.hand and chg.power and chg.zerog: 0 leaves them as they are. */
#define RTC_HAND_CLOSE 1
#define RTC_HAND_OPEN 2
#define RTC_POWER_ON 1
#define RTC_POWER_OFF 2
#define RTC_ZEROG_ON 1  /* the joints yield to a push and stay where they are left */
#define RTC_ZEROG_OFF 2

/* chg.checking: the limit checks made every sample (bits; thesis 4.5.2, checking mode). A
   check that fails ends control with the terminate code named. */
#define RTC_CHECK_OBS_POS 1 /* a joint measured outside its limits (RTC_TERM_OBSERVED_POSITION) */
#define RTC_CHECK_TGT_POS 2 /* a target outside the limits, not sent (RTC_TERM_TARGET_POSITION) */
#define RTC_CHECK_OBS_VEL 4 /* a joint measured above its top speed (RTC_TERM_OBSERVED_VELOCITY) */
#define RTC_CHECK_TGT_VEL 8 /* a commanded speed above the top speed (RTC_TERM_TARGET_VELOCITY) */
#define RTC_CHECK_FORCE 16 /* a wrist force sensor saturated or frozen (RTC_TERM_FORCE_...) */
#define RTC_CHECK_ALL 31

/* how.flags[j] bits (how.allflags: every joint's or-ed together). */
#define RTC_F_CALIBRATED 0x001       /* positions are absolute */
#define RTC_F_CALIBRATING 0x002      /* a STOPCAL is still seeking */
#define RTC_F_NOT_ANSWERING 0x004    /* the joint's controller did not answer this sample */
#define RTC_F_ENCODER_ERROR 0x008    /* its encoder failed */
#define RTC_F_OBS_POS_OUT 0x010      /* measured outside the limits */
#define RTC_F_TGT_POS_OUT 0x020      /* a target outside the limits (not sent) */
#define RTC_F_OBS_VEL_OUT 0x040      /* measured above the top speed */
#define RTC_F_TGT_VEL_OUT 0x080      /* a commanded speed above the top speed (not sent) */
#define RTC_F_NOT_CALIBRATED 0x100   /* a position target for a joint not calibrated */
#define RTC_F_PHASE_ERROR 0x200      /* the encoder's channels switched at once */
#define RTC_F_JOINT_FAULT 0x400      /* the controller reports a fault (following error) */

/* how.type[j] */
#define RTC_REVOLUTE 0  /* positions in rad (pos, valir) or deg (ang) */
#define RTC_PRISMATIC 1 /* positions in mm */

/* The values of `terminate` once control has ended (rccx codes lists them). */
#define RTC_TERM_NONE 0                 /* control runs (or never ran) */
#define RTC_TERM_USER_REQUEST 1         /* terminate set, release(), rtc_release() */
#define RTC_TERM_USER_INTERRUPT 2       /* Ctrl-C, with no user_hangup */
#define RTC_TERM_CONTROL_EXCEPTION 3    /* a control function failed (a bad chg: rtc_message) */
#define RTC_TERM_OVERRUN 10             /* a control cycle did not end within its period */
#define RTC_TERM_OBSERVED_POSITION 20   /* a joint measured outside its limits */
#define RTC_TERM_TARGET_POSITION 21     /* a joint commanded outside its limits */
#define RTC_TERM_OBSERVED_VELOCITY 22   /* a joint measured faster than its top speed */
#define RTC_TERM_TARGET_VELOCITY 23     /* a joint commanded faster than its top speed */
#define RTC_TERM_NOT_CALIBRATED 24      /* a position target for a joint not calibrated */
#define RTC_TERM_JOINT_NOT_ANSWERING 30 /* a joint's controller stopped answering (power off) */
#define RTC_TERM_ENCODER_ERROR 31       /* a joint's encoder failed */
#define RTC_TERM_POWER_FAILURE 32       /* arm power lost, or it could not be turned on */
#define RTC_TERM_PHASE_ERROR 33         /* an encoder phase error */
#define RTC_TERM_JOINT_FAULT 34         /* a joint's controller reported a fault */
#define RTC_TERM_FORCE_SATURATED 40     /* the wrist force sensor reached its range */
#define RTC_TERM_FORCE_FROZEN 41        /* the wrist force sensor stopped sending readings */

/* The state of the arm, written by the library each sample before fn1. Range values are zero
   at the joint's lower limit and grow to its range (thesis 4.5.4.1): rad for revolute joints,
   mm for prismatic ones. */
struct rtc_how {
  long sample;      /* sample number since the session opened (1, 2, ...) */
  double time_ms;   /* time of this sample, ms since the session opened */
  double period_ms; /* the sample period, ms */
  int dof;          /* joints of the robot; entries from dof on are 0 */
  double pos[RTC_MAX_JOINTS];   /* measured position, range value: rad or mm above lower limit */
  double vel[RTC_MAX_JOINTS];   /* measured speed: rad/s or mm/s */
  double ang[RTC_MAX_JOINTS];   /* measured joint value: deg (revolute) or mm (prismatic) */
  double range[RTC_MAX_JOINTS]; /* the largest range value (upper - lower limit): rad or mm */
  double lower[RTC_MAX_JOINTS]; /* the lower limit as a joint value: deg or mm (ang = lower
                                   + pos in deg or mm) */
  double vmax[RTC_MAX_JOINTS];  /* the joint's top speed: rad/s or mm/s */
  int type[RTC_MAX_JOINTS];     /* RTC_REVOLUTE or RTC_PRISMATIC */
  unsigned int flags[RTC_MAX_JOINTS]; /* RTC_F_ bits */
  unsigned int allflags;              /* every joint's flags or-ed */
  int power;                          /* 1: arm power on */
  int hand;                           /* 1: hand closed */
  int calibrated;                     /* 1: every joint calibrated (the thesis's ALL JOINTS) */
  unsigned int outputs;               /* the output bits as they stand */
};

/* One joint's command (chg.i.motion[j]). */
struct rtc_motion {
  int set;      /* RTC_NOCMD, POS, POSVEL or STOPCAL; one-shot: cleared after each function */
  double valir; /* target, range value: rad or mm above the lower limit (a float in 1986) */
  double vel;   /* POS only: rad/s or mm/s; 0: a quarter of the joint's top speed (how.vmax) */
};
struct rtc_chg_i {
  struct rtc_motion motion[RTC_MAX_JOINTS];
};
/* The command vehicle, written by fn1 and fn2. */
struct rtc_chg {
  struct rtc_chg_i i;  /* per joint: chg.i.motion[j].set, .valir, .vel */
  int hand;            /* RTC_HAND_CLOSE, RTC_HAND_OPEN, or 0; one-shot */
  int power;           /* RTC_POWER_ON, RTC_POWER_OFF, or 0; one-shot */
  int zerog;           /* RTC_ZEROG_ON, RTC_ZEROG_OFF, or 0; one-shot */
  unsigned int outset; /* output bits to set this sample; one-shot */
  unsigned int outclr; /* output bits to clear this sample; one-shot */
  int checking;        /* RTC_CHECK_ bits; kept; RTC_CHECK_ALL when control starts */
};

/* A control function (fn1, fn2): K&R `fn() { ... }` (int) or `void fn(void)`, as you like. */
typedef void (*RTC_FN)(void);
/* A hang-up function (user_hangup): K&R `hang() { ... }`; `(RTC_HANGUP)` casts others. */
#ifdef __cplusplus
typedef int (*RTC_HANGUP)(void);
#else
typedef int (*RTC_HANGUP)();
#endif

#if !defined(__cplusplus) || defined(RCCX_RTC_GLOBALS)
extern struct rtc_how how; /* the arm as read this sample (1983, thesis `how.pos[j]`) */
extern struct rtc_chg chg; /* the commands (thesis `chg.i.motion[j].set`, `.valir`) */
/* 0 while control runs. Set nonzero (by a control function) to end control: the arm holds;
   the value is kept (a nonzero value ends it as RTC_TERM_USER_REQUEST). When control ends for
   another reason the library sets it to the RTC_TERM_ code that says why. Reset to 0 by
   control() and rtc_control(). */
extern volatile long terminate;
/* 1983: a string release() prints after its argument; the program may set it any time. */
extern char* mess;
/* Thesis: a string from the control level to the user level. A control function points it at
   its text (127 characters are kept); print_terminate_code() prints it. */
extern char* rtc_message;
/* Thesis: called (on a helper thread) instead of the default when Ctrl-C is typed during
   control; the default ends control with RTC_TERM_USER_INTERRUPT. It may set terminate. Read
   when control starts. */
extern RTC_HANGUP user_hangup;
#endif

/* Thesis 2.3.1. Each returns RTC_OK or an error code (and sets rtc_error). */
int rtc_open(void);                        /* opens the session: the arm is read each period */
int rtc_control(RTC_FN fn1, RTC_FN fn2);   /* starts fn1 / fn2 each sample; after rtc_open() */
int rtc_release(int power_off);            /* stops control (the arm holds, or power off) */
int rtc_close(int power_off);              /* releases if needed and closes the session */
/* rtc_close returns RTC_OK, or RTC_E_TERMINATED (control had ended by itself), RTC_E_SEQUENCE
   (no session open), or RTC_E_LOG when RCCX_LOG's log could not be written whole: a program
   that checks it knows its log is lost. release() closes too and returns the same. */
/* 1983. control() opens the session if it is not open; release() stops control, prints msg
   (when not NULL) and then mess (when not NULL) on stdout, one line each, and closes the
   session. The arm holds (1983 shut it off: rtc_release(1) does that). Both return RTC_OK or an
   error code; release() returns RTC_E_TERMINATED when control had ended for another reason
   than the program's (a limit, a fault: terminate says which). */
int control(RTC_FN fn1, RTC_FN fn2);
int release(const char* msg);
/* Lets `ms` pass: in simulated time runs those samples, in real time sleeps. RTC_OK, or
   RTC_E_TERMINATED once control has ended (terminate says why). Ends early on Ctrl-C. */
int rtc_wait(double ms);
/* Waits until control ends or `timeout_ms` passes (negative: no limit); returns terminate
   (0 on timeout), or -1 when control was never started (rtc_error RTC_E_SEQUENCE). */
long rtc_wait_terminated(double timeout_ms);
/* Prints on stdout what `terminate` means: the code, its name, the joint and what the library
   saw, and rtc_message. */
void print_terminate_code(void);
/* The name of a terminate code ("target_position"), or "unknown". */
const char* rtc_terminate_name(long code);

#ifndef __cplusplus
/* K&R functions (int) and NULL are taken as control functions without a warning. */
#define control(fn1, fn2) control((RTC_FN)(fn1), (RTC_FN)(fn2))
#define rtc_control(fn1, fn2) rtc_control((RTC_FN)(fn1), (RTC_FN)(fn2))
#endif

#ifdef __cplusplus
}
#endif

#endif /* RCCX_COMPAT_RTC_H */
