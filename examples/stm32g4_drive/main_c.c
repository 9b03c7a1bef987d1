/* The same joint drive written in C against jointguard.h: caller-owned storage (statics),
 * the board's CAN driver given as callbacks, constants converted once with range checks. */
#include <stddef.h>

#include "board.h"
#include "joint_constants.h"
#include "jointguard.h"

/* The board's CAN driver (board.c placeholders; a real drive wraps its FDCAN driver). */
jg_can_status board_can_send(void* context, const jg_can_frame* frame);
bool board_can_receive(void* context, jg_can_frame* frame);

static jg_drive drive;

int main(void) {
  board_init();
  jg_joint_config joint = {0};
  joint.link.a_prev = LINK_A_PREV;
  joint.link.alpha_prev = LINK_ALPHA_PREV;
  joint.link.d = LINK_D;
  joint.link.mass = LINK_MASS;
  joint.link.com[0] = LINK_COM_X;
  joint.link.inertia_com[2] = LINK_INERTIA_ZZ;
  joint.link.rotor_inertia = LINK_ROTOR_INERTIA;
  joint.link.torque_constant = LINK_TORQUE_CONSTANT;
  joint.link.current_limit = LINK_CURRENT_LIMIT;
  joint.compensate_friction = true;
  joint.friction.sigma0 = LUGRE_SIGMA0;
  joint.friction.sigma1 = LUGRE_SIGMA1;
  joint.friction.sigma2 = LUGRE_SIGMA2;
  joint.friction.tau_c = LUGRE_TAU_C;
  joint.friction.tau_s = LUGRE_TAU_S;
  joint.friction.w_s = LUGRE_W_S;
  joint.observer = JG_OBSERVER_FIRST_ORDER;
  joint.gain_k1 = OBSERVER_GAIN;
  joint.threshold.base = THRESHOLD_BASE;
  joint.threshold.low_speed_extra = THRESHOLD_LOW_SPEED_EXTRA;
  joint.threshold.low_speed_width = THRESHOLD_LOW_SPEED_WIDTH;
  joint.debounce_cycles = 1;
  joint.sample_time_s = SAMPLE_TIME_S;
  jg_joint_options options = {0};
  options.hold_change_threshold = HOLD_CHANGE_THRESHOLD;
  options.hold_settle_s = HOLD_SETTLE_S;
  options.hold_reference_s = HOLD_REFERENCE_S;
  options.holding_velocity_deadband = HOLDING_VELOCITY_DEADBAND;
  const jg_drive_config config = {JOINT_NUMBER, JOINT_COUNT, 0, 0, false};
  const jg_can_port port = {NULL, board_can_send, board_can_receive, NULL, NULL};
  const double gravity[3] = {0.0, 0.0, -9.81};
  if (jg_drive_init_options(&drive, &config, &joint, &options, gravity, &port) != JG_OK) {
    board_hold_position(); /* constants that do not fit the scalar: never run */
    for (;;) {
    }
  }
  unsigned ticks = 0;
  for (;;) {
    board_wait_for_sample_tick();
    jg_drive_set_sample_holding(&drive, jg_scalar_from_double(board_link_position_rad(), NULL),
                                jg_scalar_from_double(board_link_velocity_rad_s(), NULL),
                                jg_scalar_from_double(board_motor_torque_nm(), NULL), board_holding_setpoint());
    if (!jg_drive_poll(&drive) && ++ticks % 100U == 0U) jg_drive_announce(&drive);
    jg_drive_status status;
    jg_drive_status_get(&drive, &status);
    if ((status.flags & (JG_STATUS_COLLISION | JG_STATUS_COMM_FAULT)) != 0U) board_hold_position();
  }
}
