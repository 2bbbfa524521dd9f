"""The suite's real-time premise: the CPU a cycle costs against what the CPUs give a period,
and the DDS hops of the command's path across processes."""

from __future__ import annotations

from support.capacity import CycleCost, path_hops

LOOP = ["environment_node", "observer_node", "controller_node", "device_node"]


def test_a_cycle_fits_when_its_cpu_fits_the_cpus_and_the_busiest_process_one_period() -> None:
    # composed, 45 us a cycle: fits on one CPU; four processes, 660 us in all, fit one CPU too
    assert CycleCost(45.0, 45.0, 1, 1, 0.0, 1000.0).fits()
    assert CycleCost(660.0, 230.0, 4, 1, 0.0, 1000.0).fits()
    # 900 us fits two CPUs but not one; a process of 850 us fits no number of CPUs
    assert CycleCost(900.0, 300.0, 4, 2, 0.0, 1000.0).fits()
    assert not CycleCost(900.0, 300.0, 4, 1, 0.0, 1000.0).fits()
    assert not CycleCost(850.0, 850.0, 1, 2, 0.0, 1000.0).fits()
    # what other processes keep busy is not the run's: 660 us do not fit 2 CPUs of which others
    # keep 1.5 busy
    assert not CycleCost(660.0, 230.0, 4, 2, 1.5, 1000.0).fits()
    assert CycleCost(45.0, 45.0, 1, 2, 1.7, 1000.0).fits()
    said = CycleCost(900.0, 300.0, 4, 2, 1.0, 1000.0).text()
    assert "a cycle costs 900 us of CPU across 4 process(es)" in said
    assert "0.8 x 1.00 free CPU(s) (2 less 1.00 that others kept busy) x 1000 us = 800 us" in said


def test_the_hops_of_the_command_path_across_processes() -> None:
    assert path_hops([LOOP], "OL") == 0  # composed
    assert path_hops([], "OL") == 3  # four processes: device -> environment -> controller -> device
    others = [n for n in LOOP if n != "environment_node"]
    assert path_hops([others], "OL") == 2  # the environment alone
    assert path_hops([others], "DOB") == 2
    no_observer = [n for n in LOOP if n != "observer_node"]
    assert path_hops([no_observer], "OL") == 0 and path_hops([no_observer], "DOB") == 2
