/* The C API from C (C11, -Wall -Wextra -Wpedantic -Werror): a held joint's contact torque
 * estimated through the estimator functions, parameter errors refused with their numbers,
 * and the drive on a loopback "bus" implemented here in C: booting announcement, a sync
 * built from docs/can.md's byte layout (CRC-8/AUTOSAR written here from the spec, not the
 * library's), one cycle run and its status frame checked byte by byte. Exit 0 when all hold. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "jointguard.h"

static int failures = 0;
#define CHECK(cond)                                                  \
  do {                                                               \
    if (!(cond)) {                                                   \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      ++failures;                                                    \
    }                                                                \
  } while (0)

/* CRC-8/AUTOSAR: poly 0x2F, init 0xFF, xorout 0xFF, not reflected (check "123456789" = 0xDF). */
static uint8_t crc8_autosar(const uint8_t* p, size_t n) {
  uint8_t crc = 0xFF;
  for (size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int b = 0; b < 8; ++b) crc = (uint8_t)((crc & 0x80) ? (uint8_t)((crc << 1) ^ 0x2F) : (uint8_t)(crc << 1));
  }
  return (uint8_t)(crc ^ 0xFF);
}

/* A loopback bus in C: what the drive sends is kept for inspection; frames to deliver are
 * queued by the test. */
typedef struct {
  jg_can_frame sent[16];
  int sent_count;
  jg_can_frame inbox[4];
  int inbox_count;
  int filters_set;
} bus;
static jg_can_status bus_send(void* ctx, const jg_can_frame* f) {
  bus* b = (bus*)ctx;
  if (b->sent_count >= 16) return JG_CAN_QUEUE_FULL;
  b->sent[b->sent_count++] = *f;
  return JG_CAN_OK;
}
static bool bus_receive(void* ctx, jg_can_frame* f) {
  bus* b = (bus*)ctx;
  if (b->inbox_count == 0) return false;
  *f = b->inbox[0];
  memmove(&b->inbox[0], &b->inbox[1], sizeof(jg_can_frame) * (size_t)(b->inbox_count - 1));
  --b->inbox_count;
  return true;
}
static void bus_filters(void* ctx, const jg_can_filter* filters, size_t n) {
  (void)filters;
  ((bus*)ctx)->filters_set = (int)n;
}

static jg_joint_config held_joint(void) {
  jg_joint_config c;
  memset(&c, 0, sizeof c);
  c.link.mass = 2.0;
  c.link.com[0] = 0.2;
  c.link.inertia_com[2] = 0.03;
  c.link.torque_constant = 1.0;
  c.link.current_limit = 10.0;
  c.compensate_friction = false;
  c.observer = JG_OBSERVER_FIRST_ORDER;
  c.gain_k1 = 150.0;
  c.threshold.base = 1.0;
  c.threshold.low_speed_width = 0.03;
  c.debounce_cycles = 1;
  c.sample_time_s = 0.001;
  return c;
}

/* A joint alone in its chain: the base's message without gravity and the tip's. */
static void lone_joint_ends(jg_outward_message* base, jg_inward_message* tip) {
  const double no_gravity[3] = {0.0, 0.0, 0.0};
  CHECK(jg_base_message(no_gravity, base) == JG_OK);
  jg_tip_message(tip);
}

static void estimator_on_a_held_joint(void) {
  const jg_joint_config c = held_joint();
  static jg_joint_params params; /* caller-owned storage, as on the MCU */
  static jg_joint_state state;
  CHECK(jg_joint_init(&c, &params, &state) == JG_OK);
  jg_outward_message base, to_child;
  jg_inward_message tip, to_parent;
  lone_joint_ends(&base, &tip);
  jg_error e = JG_OK;
  const jg_scalar zero = jg_scalar_from_double(0.0, &e);
  /* The motor holds 0.5 N m against a contact pushing the other way, arm at rest: the
   * estimate of the contact's torque converges to -0.5 N m (first order, K = 150 1/s: 20
   * time constants in 130 cycles) and stays below the 1 N m band: no flag. */
  const jg_scalar motor = jg_scalar_from_double(0.5, &e);
  CHECK(e == JG_OK);
  bool flag = false;
  for (int k = 0; k < 130; ++k) {
    CHECK(jg_joint_outward(&params, &state, zero, zero, &base, &to_child) == JG_OK);
    flag = jg_joint_inward_and_estimate(&params, &state, zero, motor, &tip, &to_parent);
  }
  const double est = jg_scalar_to_double(jg_joint_external_torque(&state));
  CHECK(fabs(est + 0.5) < 1e-3);
  CHECK(!flag);
  /* Then 1.5 N m: over the band, the flag rises and stays latched until reset. */
  const jg_scalar push = jg_scalar_from_double(1.5, &e);
  for (int k = 0; k < 60; ++k) {
    CHECK(jg_joint_outward(&params, &state, zero, zero, &base, &to_child) == JG_OK);
    flag = jg_joint_inward_and_estimate(&params, &state, zero, push, &tip, &to_parent);
  }
  CHECK(flag);
  jg_joint_reset_detector(&state);
  flag = jg_joint_inward_and_estimate(&params, &state, zero, motor, &tip, &to_parent);
  CHECK(jg_scalar_to_double(jg_joint_external_torque(&state)) < -1.0); /* estimate kept */
  (void)flag;
}

/* A held joint whose stiction holds 3 N m (the band's standstill allowance is 5 N m above
 * its 1 N m base, as the calibration sets it at rest): a 1.5 N m push is under the band. With
 * the holding detector (jg_joint_options) and the controller's holding state, the push is
 * a change of 1.5 N m from the value at arrival, over its 0.5 N m threshold: flagged, and
 * only while holding. */
static bool push_on_a_held_joint(const jg_joint_options* options, bool holding) {
  jg_joint_config c = held_joint();
  c.threshold.low_speed_extra = 5.0;
  jg_joint_params params;
  jg_joint_state state;
  CHECK(jg_joint_init_options(&c, options, &params, &state) == JG_OK);
  jg_outward_message base, to_child;
  jg_inward_message tip, to_parent;
  lone_joint_ends(&base, &tip);
  jg_error e = JG_OK;
  const jg_scalar zero = jg_scalar_from_double(0.0, &e);
  const jg_scalar dither = jg_scalar_from_double(0.004, &e); /* one count, within the deadband */
  bool flag = false;
  for (int k = 0; k < 400; ++k) {
    /* 3 N m held from the start, 1.5 N m more from cycle 300 (after settle and reference). */
    const jg_scalar motor = jg_scalar_from_double(k < 300 ? 3.0 : 4.5, &e);
    const jg_scalar dq = (k % 4 == 0) ? dither : zero;
    CHECK(jg_joint_outward_holding(&params, &state, zero, dq, holding, &base, &to_child) == JG_OK);
    flag = jg_joint_inward_and_estimate_holding(&params, &state, dq, motor, holding, &tip, &to_parent) || flag;
    if (k == 299) CHECK(!flag); /* nothing before the push */
  }
  CHECK(e == JG_OK);
  return flag;
}

static void holding_detector(void) {
  jg_joint_options o;
  memset(&o, 0, sizeof o); /* settle 0.15 s, reference 0.016 s by default */
  o.hold_change_threshold = 0.5;
  o.holding_velocity_deadband = 0.005;
  CHECK(push_on_a_held_joint(&o, true));
  CHECK(!push_on_a_held_joint(&o, false)); /* not holding: the band alone */
  CHECK(!push_on_a_held_joint(NULL, true)); /* no options: the band alone */
  jg_joint_params p;
  jg_joint_state s;
  const jg_joint_config c = held_joint();
  o.hold_settle_s = -1.0;
  CHECK(jg_joint_init_options(&c, &o, &p, &s) == JG_INVALID_PARAMETER);
}

static void parameter_errors(void) {
  jg_joint_params p;
  jg_joint_state s;
  jg_joint_config c = held_joint();
  c.link.mass = NAN;
  CHECK(jg_joint_init(&c, &p, &s) == JG_NOT_FINITE);
  c = held_joint();
  c.sample_time_s = 0.0;
  CHECK(jg_joint_init(&c, &p, &s) == JG_INVALID_PARAMETER);
  c = held_joint();
  c.link.mass = 1e7; /* beyond the core's link constant range */
  CHECK(jg_joint_init(&c, &p, &s) == JG_OUT_OF_RANGE);
  c = held_joint();
  c.observer = (jg_observer_kind)9;
  CHECK(jg_joint_init(&c, &p, &s) == JG_BAD_CONFIG);
  CHECK(jg_joint_init(NULL, &p, &s) == JG_NULL_ARGUMENT);
  CHECK(strcmp(jg_error_name(JG_OUT_OF_RANGE), "out_of_range") == 0);
  jg_error e = JG_OK;
  (void)jg_scalar_from_double(NAN, &e);
  CHECK(e == JG_NOT_FINITE);
}

static void drive_on_a_c_bus(void) {
  static bus b;
  static jg_drive drive;
  memset(&b, 0, sizeof b);
  const jg_can_port port = {&b, bus_send, bus_receive, NULL, bus_filters};
  const jg_drive_config dc = {1, 1, 0, 0, false};
  const jg_joint_config c = held_joint();
  const double g[3] = {0.0, 0.0, -9.81};
  CHECK(jg_drive_init(&drive, &dc, &c, g, &port) == JG_OK);
  CHECK(b.filters_set == 5); /* sync, own sensor, both neighbours, the reaction command */
  const jg_drive_config bad = {3, 2, 0, 0, false};
  CHECK(jg_drive_init(&drive, &bad, &c, g, &port) == JG_BAD_CONFIG);
  CHECK(jg_drive_init(&drive, &dc, &c, g, &port) == JG_OK);
  jg_joint_options held;
  memset(&held, 0, sizeof held);
  held.hold_change_threshold = 0.5;
  CHECK(jg_drive_init_options(&drive, &dc, &c, &held, g, &port) == JG_OK);
  held.hold_reference_s = NAN;
  CHECK(jg_drive_init_options(&drive, &dc, &c, &held, g, &port) == JG_NOT_FINITE);
  b.sent_count = 0;

  jg_drive_announce(&drive); /* before the first sync: status 0x051 with the booting flag */
  CHECK(b.sent_count == 1);
  CHECK(b.sent[0].id == 0x051 && b.sent[0].length == 8 && b.sent[0].fd);
  CHECK(b.sent[0].data[5] == JG_STATUS_BOOTING);
  CHECK(b.sent[0].data[7] == crc8_autosar(b.sent[0].data, 7));

  /* Cycle sync 0x010: seq, cycle counter (uint32 LE), 2 B reserved, CRC (docs/can.md). */
  jg_can_frame sync;
  memset(&sync, 0, sizeof sync);
  sync.id = 0x010;
  sync.length = 8;
  sync.fd = true;
  const uint32_t cycle = 7;
  sync.data[0] = (uint8_t)cycle;
  sync.data[1] = (uint8_t)cycle;
  sync.data[7] = crc8_autosar(sync.data, 7);
  b.inbox[b.inbox_count++] = sync;
  jg_error e = JG_OK;
  jg_drive_set_sample_holding(&drive, jg_scalar_from_double(0.1, &e), jg_scalar_from_double(0.0, &e),
                              jg_scalar_from_double(0.0, &e), true);
  CHECK(jg_drive_poll(&drive));
  CHECK(b.sent_count == 2);
  const jg_can_frame* st = &b.sent[1];
  CHECK(st->id == 0x051 && st->length == 8);
  CHECK(st->data[0] == (uint8_t)cycle);
  CHECK(st->data[7] == crc8_autosar(st->data, 7));
  jg_drive_status s;
  jg_drive_status_get(&drive, &s);
  CHECK(s.cycles == 1 && s.last_cycle == cycle);
  CHECK((s.flags & JG_STATUS_BOOTING) == 0);
  /* A corrupted sync is rejected: no cycle, counted. */
  sync.data[0] = 8;
  sync.data[1] = 8;
  b.inbox[b.inbox_count++] = sync; /* CRC now wrong */
  CHECK(!jg_drive_poll(&drive));
  jg_drive_status_get(&drive, &s);
  CHECK(s.cycles == 1);
}

int main(void) {
  estimator_on_a_held_joint();
  parameter_errors();
  holding_detector();
  drive_on_a_c_bus();
  printf("jointguard C API (%s, %d.%d.%d): %s\n", jg_scalar_name(), JG_VERSION_MAJOR, JG_VERSION_MINOR,
         JG_VERSION_PATCH, failures == 0 ? "all checks passed" : "FAILED");
  return failures == 0 ? 0 : 1;
}
