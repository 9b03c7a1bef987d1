/* jointguard C API: one joint's estimation cycle and the joint drive on the bus, for drive
 * firmware written in C.
 *
 * - No allocation, no global state: every object lives in storage the caller owns
 *   (a static, a stack variable or a member of the caller's own struct). The storage sizes
 *   are compile-time constants (JG_*_BYTES); the library checks at its own build that its
 *   objects fit them, so a C caller never needs the C++ types.
 * - The scalar is the package's, chosen once when the library was built (CMake option
 *   JG_SCALAR; the exported targets define JG_SCALAR_Q): jg_scalar is float, or the raw
 *   int32 of a Q16.16 value (SI units times 65536). Parameters are given in double (SI
 *   units) and converted with range checks at initialisation, never in the cycle.
 * - Errors are jg_error values with stable numbers (the C++ core's jg::Error plus the
 *   API's own from 100 on).
 * - Thread safety: none needed inside; one object is used by one context (the control
 *   loop), as on the drive's MCU.
 */
#ifndef JOINTGUARD_H
#define JOINTGUARD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define JG_VERSION_MAJOR 0
#define JG_VERSION_MINOR 2
#define JG_VERSION_PATCH 0

#ifndef JG_SCALAR_Q
#define JG_SCALAR_Q 0
#endif
#if JG_SCALAR_Q
typedef int32_t jg_scalar; /* Q16.16: value = raw / 65536 */
#else
typedef float jg_scalar;
#endif

/* Stable numbers: the first four are the core's jg::Error. */
typedef enum {
  JG_OK = 0,
  JG_NOT_FINITE = 1,        /* NaN or infinity in an input or parameter */
  JG_OUT_OF_RANGE = 2,      /* a value does not fit the firmware scalar */
  JG_INVALID_PARAMETER = 3, /* physically meaningless (negative stiffness, zero sample time...) */
  JG_NULL_ARGUMENT = 100,   /* a required pointer is NULL */
  JG_BAD_CONFIG = 101       /* joint numbering or observer kind outside what the core supports */
} jg_error;

/* The joint's link in modified Denavit-Hartenberg form, as in the project's robot file
 * (docs/robot-model.md): lengths [m], angles [rad], mass [kg], centre of mass [m] and
 * inertia about it [kg m^2] (xx, yy, zz, xy, xz, yz) in the link frame, rotor inertia
 * reflected to the link side [kg m^2], K_I [N m/A], current limit [A]. */
typedef struct {
  double a_prev, alpha_prev, d, theta_offset;
  double mass;
  double com[3];
  double inertia_com[6];
  double rotor_inertia, torque_constant, current_limit;
} jg_link_description;

/* LuGre friction as identified (`jointguard identify` JSON): sigma0 [N m/rad],
 * sigma1, sigma2 [N m s/rad], tau_c, tau_s [N m], w_s [rad/s]. */
typedef struct {
  double sigma0, sigma1, sigma2, tau_c, tau_s, w_s;
} jg_lugre;

/* Observer kinds (stable numbers, as jg::ObserverKind). */
typedef enum {
  JG_OBSERVER_FIRST_ORDER = 0,
  JG_OBSERVER_LOWPASS2 = 1,
  JG_OBSERVER_PAPER_BANDPASS = 2,
  JG_OBSERVER_PAPER_IMPROVED = 3
} jg_observer_kind;

/* Detection band eps(w) = base + per_speed |w| + low_speed_extra exp(-(w / low_speed_width)^2)
 * [N m, N m s/rad, N m, rad/s] (`jointguard calibrate` JSON). */
typedef struct {
  double base, per_speed, low_speed_extra, low_speed_width;
} jg_threshold;

typedef struct {
  jg_link_description link;
  bool compensate_friction; /* false: `friction` is ignored */
  jg_lugre friction;
  jg_observer_kind observer;
  double gain_k1, gain_k2, gain_k3; /* [1/s] */
  jg_threshold threshold;
  uint8_t debounce_cycles; /* consecutive cycles over the band (0 is taken as 1) */
  double sample_time_s;    /* the control period */
} jg_joint_config;

/* Optional features beyond jg_joint_config (since 0.2), for jg_joint_init_options and
 * jg_drive_init_options. All zero (or a NULL pointer) is what jg_joint_init and
 * jg_drive_init do.
 * - Holding-aware change detection (issue 15; jointguard/detection/hold_detector.hpp):
 *   while the drive's controller holds a constant setpoint (the `holding` argument of the
 *   *_holding calls), the friction it holds is constant, so a contact shows as a change of
 *   the estimate from its value on arrival, whatever the stiction holds.
 *   hold_change_threshold [N m]: `jointguard calibrate --holding`'s hold_change_threshold
 *   (<= 0: off); hold_settle_s: held time skipped after arrival (0: 0.15 s);
 *   hold_reference_s: held time averaged into the reference (0: 0.016 s, at least one sample).
 * - holding_velocity_deadband [rad/s]: while holding, a measured |dq| up to this is taken as
 *   0 (the one-count dither of a joint at rest); 1-2 motor-encoder counts per sample; 0: off.
 * - align_motor_torque: the observer balances the momentum change with the mean of the last
 *   two motor torques (jointguard/observer/momentum_observer.hpp; off by default, see
 *   docs/history.md "Motor torque aligned in the observer"). */
typedef struct {
  double hold_change_threshold;
  double hold_settle_s;
  double hold_reference_s;
  double holding_velocity_deadband;
  bool align_motor_torque;
} jg_joint_options;

/* Messages between neighbouring joints (the momentum recursion), in jg_scalar. */
typedef struct {
  jg_scalar angular_velocity[3]; /* [rad/s] */
  jg_scalar origin_velocity[3];  /* [m/s] */
  jg_scalar gravity[3];          /* [m/s^2] */
} jg_outward_message;
typedef struct {
  jg_scalar angular_momentum[3]; /* [N m s] */
  jg_scalar linear_momentum[3];  /* [N s] */
  jg_scalar first_moment[3];     /* [kg m] */
  jg_scalar mass;                /* [kg] */
} jg_inward_message;

/* Caller-owned storage. Upper bounds, checked against the library's objects when it is
 * built (static_assert in jointguard_c.cpp); aligned for any scalar member. */
#define JG_JOINT_PARAMS_BYTES 512u
#define JG_JOINT_STATE_BYTES 512u
#define JG_DRIVE_BYTES 3072u
typedef union {
  unsigned char bytes[JG_JOINT_PARAMS_BYTES];
  long double align_;
  uint64_t align64_;
  void* alignp_;
} jg_joint_params;
typedef union {
  unsigned char bytes[JG_JOINT_STATE_BYTES];
  long double align_;
  uint64_t align64_;
  void* alignp_;
} jg_joint_state;

/* ---- scalar conversion (not for the cycle: Q16.16 conversion goes through double) ---- */
/* Saturates into the scalar's range; *error (may be NULL) gets JG_OUT_OF_RANGE or
 * JG_NOT_FINITE when the value did not fit, JG_OK otherwise. */
jg_scalar jg_scalar_from_double(double value, jg_error* error);
double jg_scalar_to_double(jg_scalar value);
const char* jg_scalar_name(void);    /* "float" or "q16.16" */
const char* jg_error_name(jg_error error); /* "ok", "not_finite", ... */

/* ---- one joint's estimation cycle (no bus: the caller moves the messages) ---- */
/* Converts the configuration (range checks) into params and resets the state. On error
 * neither is usable and the error names the part: see jg_error. */
jg_error jg_joint_init(const jg_joint_config* config, jg_joint_params* params, jg_joint_state* state);
/* The first joint's parent message: the base at rest with gravity g [m/s^2] in the base frame. */
jg_error jg_base_message(const double gravity[3], jg_outward_message* out);
/* The last joint's child message: nothing beyond the tip. */
void jg_tip_message(jg_inward_message* out);
/* Phase 1: own position q [rad], velocity dq [rad/s] and the parent's message -> the
 * child's. JG_NOT_FINITE (float builds): the last good message is repeated, the state
 * is kept and the cycle is marked faulty. */
jg_error jg_joint_outward(const jg_joint_params* params, jg_joint_state* state, jg_scalar q, jg_scalar dq,
                          const jg_outward_message* from_parent, jg_outward_message* to_child);
/* Phase 2: the child's message -> the parent's; then friction, observer and detector.
 * motor_torque at the link side [N m]. Returns the joint's (latched) collision flag. */
bool jg_joint_inward_and_estimate(const jg_joint_params* params, jg_joint_state* state, jg_scalar dq,
                                  jg_scalar motor_torque, const jg_inward_message* from_child,
                                  jg_inward_message* to_parent);
/* jg_joint_init with the optional features (options may be NULL: none). JG_NOT_FINITE,
 * JG_INVALID_PARAMETER (a negative time or deadband) or JG_OUT_OF_RANGE (a settle or
 * reference time over 65535 samples, a value the scalar cannot hold) leave both untouched. */
jg_error jg_joint_init_options(const jg_joint_config* config, const jg_joint_options* options, jg_joint_params* params,
                               jg_joint_state* state);
/* Phases 1 and 2 of a drive that reports holding: `holding` is its controller's state this
 * cycle (a constant setpoint). Give both phases the same value. */
jg_error jg_joint_outward_holding(const jg_joint_params* params, jg_joint_state* state, jg_scalar q, jg_scalar dq,
                                  bool holding, const jg_outward_message* from_parent, jg_outward_message* to_child);
bool jg_joint_inward_and_estimate_holding(const jg_joint_params* params, jg_joint_state* state, jg_scalar dq,
                                          jg_scalar motor_torque, bool holding, const jg_inward_message* from_child,
                                          jg_inward_message* to_parent);
/* The estimate of the contact's torque on this joint [N m], and the friction predicted. */
jg_scalar jg_joint_external_torque(const jg_joint_state* state);
jg_scalar jg_joint_friction_torque(const jg_joint_state* state);
/* Clears the latched collision flag (after the reaction has been handled). */
void jg_joint_reset_detector(jg_joint_state* state);

/* ---- the joint drive on a CAN (FD) bus (docs/can.md: protocol, sync pacing) ---- */
typedef struct {
  uint32_t id;           /* 11-bit or 29-bit identifier */
  uint8_t length;        /* payload bytes (FD: 0..8, 12, 16, 20, 24, 32, 48, 64) */
  bool fd;               /* CAN FD frame (bit-rate switch) */
  bool extended;         /* 29-bit identifier */
  uint64_t timestamp_us; /* receive time */
  uint8_t data[64];
} jg_can_frame;
typedef enum { JG_CAN_OK = 0, JG_CAN_QUEUE_FULL = 1, JG_CAN_BUS_OFF = 2, JG_CAN_INVALID = 3 } jg_can_status;
typedef enum { JG_CAN_ERROR_ACTIVE = 0, JG_CAN_ERROR_PASSIVE = 1, JG_CAN_BUS_OFF_STATE = 2 } jg_can_error_state;
typedef struct {
  uint32_t match, mask; /* passes when (id & mask) == (match & mask) */
} jg_can_filter;
/* The board's CAN driver, as callbacks (the C counterpart of the HAL's port contract).
 * send: queue a frame, never block. receive: the next accepted frame, false when none.
 * error_state and set_filters may be NULL (error-active; no hardware filters). */
typedef struct {
  void* context;
  jg_can_status (*send)(void* context, const jg_can_frame* frame);
  bool (*receive)(void* context, jg_can_frame* frame);
  jg_can_error_state (*error_state)(void* context);
  void (*set_filters)(void* context, const jg_can_filter* filters, size_t count);
} jg_can_port;

typedef struct {
  uint8_t joint;          /* 1-based position in the chain */
  uint8_t joints;         /* chain length (<= 7) */
  uint8_t fault_cycles;   /* cycles without a fresh neighbour frame before the fault (0: 5) */
  uint8_t max_age_cycles; /* older neighbour frames are late (0: 2) */
  bool sensors_over_can;  /* host-in-the-loop: samples arrive as sensor frames */
} jg_drive_config;

typedef union {
  unsigned char bytes[JG_DRIVE_BYTES];
  long double align_;
  uint64_t align64_;
  void* alignp_;
} jg_drive;

/* Status flag bits of the drive (as in the status frame, docs/can.md). */
#define JG_STATUS_COLLISION 0x01u
#define JG_STATUS_COMM_FAULT 0x02u
#define JG_STATUS_READY 0x04u
#define JG_STATUS_INPUT_FAULT 0x08u
#define JG_STATUS_BOOTING 0x10u

typedef struct {
  jg_scalar external_torque; /* [N m] */
  uint8_t flags;             /* JG_STATUS_* */
  uint8_t rejected;          /* rejected frames, saturating at 255 */
  uint32_t cycles;           /* cycles run */
  uint32_t last_cycle;       /* the last sync's cycle counter */
} jg_drive_status;

/* Builds the drive in `drive` (the port is copied: its context must outlive the drive).
 * gravity [m/s^2] in the base frame (only joint 1 uses it). */
jg_error jg_drive_init(jg_drive* drive, const jg_drive_config* config, const jg_joint_config* joint,
                       const double gravity[3], const jg_can_port* port);
/* The drive's own sample before the sync (MCU: encoder and current ADC). */
void jg_drive_set_sample(jg_drive* drive, jg_scalar position, jg_scalar velocity, jg_scalar motor_torque);
/* jg_drive_init with the optional features (options may be NULL), and the sample with the
 * controller's holding state (the sensor frame's holding byte when sensors_over_can). */
jg_error jg_drive_init_options(jg_drive* drive, const jg_drive_config* config, const jg_joint_config* joint,
                               const jg_joint_options* options, const double gravity[3], const jg_can_port* port);
void jg_drive_set_sample_holding(jg_drive* drive, jg_scalar position, jg_scalar velocity, jg_scalar motor_torque,
                                 bool holding);
/* Before the first sync: a status frame with the booting flag (call every ~100 ms). */
void jg_drive_announce(jg_drive* drive);
/* Reads every received frame; runs the cycle once its sync (and sample) are in. True when a
 * cycle ran. */
bool jg_drive_poll(jg_drive* drive);
void jg_drive_status_get(const jg_drive* drive, jg_drive_status* out);

#ifdef __cplusplus
}
#endif
#endif /* JOINTGUARD_H */
