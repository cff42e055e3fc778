// The device API functions that read or change a trace (lucent/device/api.h), defined once
// over the trace state machine. A backend includes this file once, after it defines
// lucent::runtime::backend(): the policy of the calling thread (trace_rules.h).
#pragma once

#include "runtime/trace_rules.h"

namespace lucent {

LUCENT_HD const Ray& current_ray() {
    return runtime::current_ray(runtime::backend());
}
LUCENT_HD float ray_time() {
    return runtime::current_ray(runtime::backend()).time;
}
LUCENT_HD float t_hit() {
    return runtime::t_hit(runtime::backend());
}
LUCENT_HD unsigned primitive_index() {
    return runtime::primitive_index(runtime::backend());
}
LUCENT_HD unsigned instance_id() {
    return runtime::instance_id(runtime::backend());
}
LUCENT_HD unsigned geometry_instance_id() {
    return runtime::geometry_instance_id(runtime::backend());
}
LUCENT_HD bool potential_intersection(float t) {
    return runtime::potential_intersection(runtime::backend(), t);
}
LUCENT_HD bool report_intersection(unsigned material_index) {
    return runtime::report_intersection(runtime::backend(), material_index);
}

namespace detail {
LUCENT_HD bool current_transform(const Matrix4x3*& to_world, const Matrix4x3*& to_object) {
    return runtime::current_transform(runtime::backend(), to_world, to_object);
}
LUCENT_HD void end_any_hit(AnyHitOutcome outcome) {
    runtime::end_any_hit(runtime::backend(), outcome);
}
}  // namespace detail

}  // namespace lucent
