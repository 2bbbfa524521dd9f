# Sourced by the ros2 run shims next to it (not an executable). The ROS 2 wheels' bootstrapper
# (ros_wheels_bootstrapper) sets the library path by re-executing Python once at start-up; a
# Ctrl-C that falls between the two interpreters is lost. The shims set the same path before
# Python starts, so it never re-executes.
if [ -z "${_ROS_WHEELS_BOOTSTRAP_COMPLETE:-}" ]; then
    _prefix="$(cd "$(dirname "$0")/../.." && pwd)"
    _libs="$_prefix/lib"
    for _d in "$_prefix"/lib/python3*/site-packages/ros_*.libs; do
        if [ -d "$_d" ]; then _libs="$_libs:$_d"; fi
    done
    LD_LIBRARY_PATH="$_libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    _ROS_WHEELS_BOOTSTRAP_COMPLETE=1
    export LD_LIBRARY_PATH _ROS_WHEELS_BOOTSTRAP_COMPLETE
fi
# A Ctrl-C (ros2 launch, a terminal) that comes before the node's entry point has set its quiet
# handler would make Python print a KeyboardInterrupt traceback from its own start-up (its site
# packages, the entry point's imports). SIGINT stays ignored until then: Python keeps an ignored
# SIGINT ignored, and haptic_dob.runtime.entry.run_main takes it over. A Ctrl-C in those first
# moments is lost; ros2 launch follows it with SIGTERM, a terminal's user presses again.
trap '' INT
