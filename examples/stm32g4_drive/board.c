/* Placeholder board layer: compiles and links; replace with the drive's own. */
#include "board.h"

void board_init(void) {}
void board_wait_for_sample_tick(void) {}
double board_link_position_rad(void) { return 0.0; }
double board_link_velocity_rad_s(void) { return 0.0; }
double board_motor_torque_nm(void) { return 0.0; }
bool board_holding_setpoint(void) { return false; }
void board_hold_position(void) {}

#include "jointguard.h"
jg_can_status board_can_send(void* context, const jg_can_frame* frame);
bool board_can_receive(void* context, jg_can_frame* frame);
jg_can_status board_can_send(void* context, const jg_can_frame* frame) {
  (void)context;
  (void)frame;
  return JG_CAN_OK;
}
bool board_can_receive(void* context, jg_can_frame* frame) {
  (void)context;
  (void)frame;
  return false;
}
