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
