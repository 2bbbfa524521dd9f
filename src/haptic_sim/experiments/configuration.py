"""The report's first table: the one plant, hand, observer rule and analysis every part runs,
each value with its source."""

from __future__ import annotations

from haptic_dob.analysis.transparency import MIN_AVERAGES, segment_for
from haptic_sim.experiments.observer_gain import ACCURACY_GAIN, gain_for
from haptic_sim.experiments.plan import CH7_WALLS
from haptic_sim.experiments.records import ExperimentResults
from haptic_sim.experiments.tables import fmt
from haptic_sim.hand import depth_reference
from haptic_sim.slide.session import SessionConfig
from haptic_sim.slide.stability import THRESHOLD_PLATEAU_M


def config_table(res: ExperimentResults, base: SessionConfig) -> str:
    """The one plant and the one observer configuration every part runs, and what each part sets
    on top (the hand, the wall, the protocol)."""
    m, s, h, d, o = base.model, base.sensor, base.hand, base.device, base.observer
    seg = segment_for(38.0)  # chapter 7's 40 s after the 2 s ramp-in
    gains = ", ".join(
        f"Kf = {kf:g}: {gain_for(kf, ACCURACY_GAIN, base)[0]:g} (chatter above "
        f"{fmt(gain_for(kf, ACCURACY_GAIN, base)[1], '.1f', 'none')})"
        for kf in (1.0, 2.0, 25.0, 100.0)
    )
    ref = depth_reference(h, tuple(CH7_WALLS), m.mass_kg, m.viscous_n_s_per_m, d.max_force_n)
    pushes = ", ".join(f"{ref.push_n[w]:.2f} N at {w:g}" for w in CH7_WALLS)
    rows = [
        (
            "simulated slide (its truth, `plant.*`)",
            f"m {d.mass_kg} kg, viscous {d.viscous_n_s_per_m} N s/m, Coulomb {d.coulomb_n} N, "
            f"static {d.stiction_ratio:g} x Coulomb over {1e3 * d.stribeck_velocity_m_per_s:g} "
            f"mm/s (Stribeck), amplifier lag {1e3 * d.amplifier_lag_s:g} ms",
        ),
        (
            "the observer's and controller's model (`slide.*`)",
            f"m {m.mass_kg} kg, viscous {m.viscous_n_s_per_m} N s/m, Coulomb {m.coulomb_n} N: "
            "least squares on chapter 4's 2.4 N bag (`haptic-identify "
            "runs/ch4_step_2p4/bag`) to 4 digits (chapter 4 checks it)",
        ),
        (
            "observer gain c (N s/m), per Kf",
            f"{gains}: the gain whose estimate is closest to the force sensor in 5.3's free and "
            f"wall sessions ({ACCURACY_GAIN:g}), or the fastest whole gain below the one at which "
            "DOB at that Kf chatters at the sample rate if that is smaller "
            "(`haptic_sim.experiments.observer_gain`; the node's default, for any Kf, is "
            f"{o.gain:g}); output limit {o.output_limit} N",
        ),
        ("loop", f"{base.loop.rate_hz:g} Hz, {base.loop.substeps} physics sub-steps, lockstep"),
        (
            "transparency analysis",
            f"H1 (Welch, Hann, 50 % overlap) after the first 2 s: {seg:g} s segments for a 40 s "
            f"session ({1 / seg:g} Hz bins; 4 s where they average at least "
            f"{MIN_AVERAGES}, else 2 s: Bendat and Piersol's random error near 9 % at a coherence "
            "of 0.8); "
            "a band whose first bin is already outside the 3 dB band ends below it and is shown "
            f"`< {1 / seg:g}` (a floor, never within 15 % of the thesis)",
        ),
        (
            "vibration felt (ch. 6's tap)",
            "the residual's peak above the vibrotactile detection threshold at its frequency: "
            f"{THRESHOLD_PLATEAU_M * 1e6:g} um up to 40 Hz (the non-Pacinian I channel), the "
            "Pacinian channel's U above (Bolanowski, Gescheider, Verrillo and Checkosky 1988, "
            '"Four channels mediate the mechanical aspects of touch"; thesis 6.2: the user '
            "judged by feel)",
        ),
        ("actuator", f"saturation {d.max_force_n} N, encoder {d.encoder_resolution_m} m"),
        (
            "force sensor",
            f"bandwidth {s.bandwidth_hz} Hz, noise {s.noise_std_n} N RMS, bias {s.bias_n} N",
        ),
        ("controller", f"saturation {base.law.max_force_n} N"),
        (
            "hand, ch. 5 and 7",
            f"{h.behaviour}: mass {h.mass_kg} kg, grip {h.stiffness_n_per_m} N/m, "
            f"damping {h.damping_n_s_per_m} N s/m; one reference at every wall, a depth (thesis "
            f"7.3.2): offset {1e3 * h.offset_m:g} mm, std {1e3 * h.amplitude_m:g} mm (pushing "
            f"{pushes} N/m: half the actuator's {d.max_force_n:g} N at the stiffest, the slide in "
            f"contact over 3 sigma at every wall; `haptic_sim.hand.depth_reference`); band "
            f"{h.band_low_hz}-{h.band_high_hz} Hz rolled off above {h.rolloff_hz:g} Hz, the end "
            'of voluntary motion (Brooks 1990, "Telerobotic response requirements"); seed '
            f"{res.seed}",
        ),
        (
            "hand, ch. 6",
            "push-and-hold: 1 N through a 20 N/m grip, no hand mass or damping; a 0.5 N x 5 ms "
            "pulse (linear protocol) or a 3 N x 20 ms tap at 1.5 s",
        ),
        (
            "set per part",
            "ch. 4: OL, no hand, an 80 N/m two-sided spring and a known force; ch. 6's linear "
            "protocol only: Coulomb friction 0 in the plant and the model, the premise of the "
            "passivity bounds (with it OL and CL keep no vibration: the tap table). Nothing "
            "else changes the plant or the observer; the batch sweeps change one parameter "
            "each, named in their tables",
        ),
    ]
    head = (
        f"Base config `{res.config}` (node parameters in `results.json`, `config_params`); "
        "each run's full parameter file is `runs/<run>/params.yaml`, and its bag records every "
        "node's parameters.\n\n| | |\n|---|---|\n"
    )
    return head + "\n".join(f"| {k} | {v} |" for k, v in rows) + "\n"
