"""An arm's model from its joint states: rigid body, armature and joint friction beyond CAD.

ROS-free. The URDF gives the kinematics and CAD values, the record joint positions and applied
efforts (positions differentiated through ``filters``). Effort = ``W theta`` (``arm_parameters``):
1. the regressor on the first ``1 - holdout`` of the record (filters' ends, lost states and
   still stretches out; decimated), on the light motion, filtered like the effort;
2. each base parameter's visibility: one below ``min_visibility`` is refused, named;
3. least squares (Coulomb a filtered sign), each joint's ``v_c`` (``arm_friction.turn_speed``),
   least squares again on each joint's rows clear of its turns (``clear_rows``), then
   weighted by each joint's residual RMS (``arm_normal``);
4. a physically consistent full set (``arm_consistent``) drawn toward CAD, checked: mass > 0,
   centre of mass in the link's box (the origins its link carries and the CAD inertia's
   equivalent box, plus ``margin_m``), pseudo-inertia positive definite;
5. each joint's held-out RMS residual against its torque span, identified and CAD.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from haptic_dob.core.models import UrdfModel
from haptic_dob.core.models._pinocchio_inertia import Body, bodies, body_parameters, moved
from haptic_dob.identification import arm_parameters as ap
from haptic_dob.identification.arm_consistent import (
    ConsistentFit,
    Link,
    fit_consistent,
    pseudo_inertia,
)
from haptic_dob.identification.arm_friction import coulomb_term, turn_filters, turn_speed
from haptic_dob.identification.arm_model_report import ArmModelFit, joint_fits, link_fit
from haptic_dob.identification.arm_normal import Normal, condition_number, solve, square_root
from haptic_dob.identification.arm_urdf import LinkInertial, link_inertials
from haptic_dob.identification.filters import (
    HELD_S,
    MIN_SPEED,
    IdentificationError,
    MotionFilters,
)

Arr = NDArray[np.float64]
#: a base parameter the record determines with more than 1 / this the variance per sample that
#: motion across the joints' ranges gives is not seen (``arm_parameters.visibility``)
MIN_VISIBILITY = 1e-4
#: a link without CAD mass is drawn toward this (kg)
MASS_FLOOR_KG = 1e-3


@dataclass(frozen=True)
class Record:
    """Joint states: stamps (ns), positions and efforts over [k-1, k) (N, dof), joint names."""

    stamps_ns: NDArray[np.int64]
    position: Arr
    effort: Arr
    names: tuple[str, ...]


def identify_arm_model(
    urdf: str,
    tip_frame: str,
    record: Record,
    *,
    cutoff_hz: float = 20.0,
    holdout: float = 0.3,
    turn_cutoff_hz: float | None = None,
    margin_m: float = 0.02,
    min_visibility: float = MIN_VISIBILITY,
) -> ArmModelFit:
    """The arm's model from ``record`` (its joints the URDF's chain to ``tip_frame``, or the
    joints it names, in its order); ``IdentificationError`` with one line when it cannot."""
    cad = UrdfModel(urdf, tip_frame, list(record.names))
    lay = ap.layout_of(cad)
    n, dof = record.position.shape
    if record.effort.shape != (n, dof) or dof != cad.dof:
        raise IdentificationError(f"the record has {dof} joints, the model {cad.dof}")
    if n < 500:
        raise IdentificationError(f"too short: {n} samples, need 500")
    dt = float(np.median(np.diff(record.stamps_ns))) * 1e-9
    if not (
        dt > 0.0 and np.all(np.isfinite(record.position)) and np.all(np.isfinite(record.effort))
    ):
        raise IdentificationError("the stamps do not increase, or a value is not finite")
    f = MotionFilters.design(dt, cutoff_hz)
    wide = f if turn_cutoff_hz is None else turn_filters(dt, cutoff_hz, turn_cutoff_hz)
    position = np.unwrap(record.position, axis=0)
    x, _, _ = f.motion(position)
    tau = f.effort(record.effort)
    v_light = f.light_velocity(position)
    split = int((1.0 - holdout) * n)
    idx = np.arange(2 * f.window, split, f.step)
    test_idx = np.arange(split, n - 2 * f.window, f.step)
    if len(test_idx) < 10 or len(idx) * dof < 3 * lay.size:
        raise IdentificationError(f"too short: {len(idx)} samples to fit, {len(test_idx)} held out")
    speed = np.abs(v_light).max(axis=1)
    live = f.fit_rows(record.stamps_ns, speed)
    idx, test_idx = idx[live[idx]], test_idx[live[test_idx]]
    if len(test_idx) < 10 or len(idx) * dof < 3 * lay.size:
        lost, still = ~f.contiguous(record.stamps_ns), f.held(speed, MIN_SPEED, HELD_S)
        raise IdentificationError(
            f"too little motion: {len(idx)} samples to fit, {len(test_idx)} held out, once the "
            f"filters' reach of lost states ({int(lost.sum())} samples) and of stretches still "
            f"for {HELD_S:g} s ({int(still.sum())} samples) is left out"
        )
    sign = f.coulomb_term(v_light)
    light = light_regressor(cad, f, position)
    W_all = f.smooth(light).reshape(n, dof, -1)
    W = ap.with_coulomb(W_all[idx].reshape(len(idx) * dof, -1), sign[idx])
    y = tau[idx].ravel()
    W_ref = ap.regressor(cad, *ap.reference_states(cad, ap.REFERENCE_STATES))
    bs = ap.base_set(W_ref)
    names = bs.names(lay)
    normal = Normal.of(W, y, dof)
    G, b, yy = normal.total()
    G_ref = W_ref.T @ W_ref / ap.REFERENCE_STATES
    seen = ap.visibility(G[np.ix_(bs.base, bs.base)] / len(idx), G_ref[np.ix_(bs.base, bs.base)])
    unseen = ap.unseen_names(names, seen, min_visibility)
    if unseen:
        more = f" and {len(unseen) - 8} more" if len(unseen) > 8 else ""
        raise IdentificationError(
            f"too little excitation: the record does not see {', '.join(unseen[:8])}{more} (its "
            f"motion determines each less than {min_visibility:g} as well as motion across the "
            "joints' ranges would); record a richer excitation (haptic-excite)"
        )
    beta, _, _ = solve(G, b, yy, len(y), bs.base, "the arm")
    speeds = _turn_speeds(
        (f, wide),
        (position, record.effort, v_light, light),
        (W, y, idx, split, wide.fit_rows(record.stamps_ns, speed)),
        bs,
        beta,
        lay,
    )
    coulomb = np.column_stack([coulomb_term(f, v_light[:, j], c) for j, c in enumerate(speeds)])
    W = ap.with_coulomb(W, coulomb[idx])
    normal = Normal.of(W, y, dof, clear_rows(f, v_light, speeds, idx))
    beta, _, _ = solve(*normal.total(), normal.rows, bs.base, "the arm")
    weight = 1.0 / np.maximum(normal.residual_rms(bs.base, beta), 1e-12)  # each joint's rows
    Gw, bw, yyw = normal.total(weight)
    beta, std, sigma = solve(Gw, bw, yyw, normal.rows, bs.base, "the arm")
    inertials = link_inertials(urdf)
    links = [_link(b, inertials, margin_m) for b in bodies(cad)]
    cad_joint = np.concatenate([cad.armature, cad.viscous, cad.coulomb])
    scale = _joint_scales(cad, x[idx], (beta, std), bs, lay)
    start = cad_joint.copy()
    at = bs.base >= lay.rigid
    start[bs.base[at] - lay.rigid] = beta[at]  # least squares' friction and armature
    R, z = square_root(Gw, bw)
    found = fit_consistent(R, z, sigma, links, (cad_joint, scale, start))
    _check(lay.links, links, found)
    W_held = ap.with_coulomb(W_all[test_idx].reshape(len(test_idx) * dof, -1), coulomb[test_idx])
    cad_theta = np.concatenate([body_parameters(cad).ravel(), cad_joint])
    pred = (W_held @ found.theta).reshape(len(test_idx), dof)
    pred_cad = (ap.with_coulomb(W_held, sign[test_idx]) @ cad_theta).reshape(len(test_idx), dof)
    heldout = (tau[test_idx] - pred, tau[test_idx] - pred_cad, np.ptp(tau[test_idx], axis=0))
    return ArmModelFit(
        links=tuple(
            link_fit(n, k, c) for n, k, c in zip(lay.links, links, found.links, strict=True)
        ),
        joints=joint_fits(lay.joints, found, speeds, heldout),
        holdout=holdout,
        samples=len(idx),
        condition_number=condition_number(normal.total()[0], bs.base),
        visibility=tuple((nm, float(v_)) for nm, v_ in zip(names, seen, strict=True)),
        unidentifiable=tuple(lay.names[i] for i in bs.dependent),
    )


def clear_rows(
    f: MotionFilters, v_light: Arr, speeds: Sequence[float], idx: NDArray[np.intp]
) -> NDArray[np.bool_]:
    """Each joint's rows (samples ``idx``) where it moves clear of its Coulomb term's turns
    (``MotionFilters.clear_of_turns``), one column per joint."""
    return np.column_stack(
        [f.clear_of_turns(v_light[:, j], c, MIN_SPEED, idx) for j, c in enumerate(speeds)]
    )


def light_regressor(cad: UrdfModel, f: MotionFilters, position: Arr) -> Arr:
    """The regressor (Coulomb columns zero) of every sample on ``f``'s light motion, one row
    per sample (N, dof * parameters): ``f.smooth`` of it is the filtered regressor."""
    n, dof = position.shape
    x, v, a = f.light_motion(position)
    return ap.regressor(cad, x, v, a, np.zeros((n, dof))).reshape(n, -1)


def _turn_speeds(
    filters: tuple[MotionFilters, MotionFilters],
    raw: tuple[Arr, Arr, Arr, Arr],
    fitted: tuple[Arr, Arr, NDArray[np.intp], int, NDArray[np.bool_]],
    bs: ap.BaseSet,
    beta: Arr,
    lay: ap.Layout,
) -> list[float]:
    """Each joint's ``v_c`` (``arm_friction.turn_speed``) on the effort the fitted rigid body and
    armature leave; ``raw``: positions, efforts, light velocity, the light motion's regressor
    (``light_regressor``); ``fitted``: W, y, samples, the held-out part's start and the samples
    the wide filters' fit may use (``MotionFilters.fit_rows``)."""
    f, wide = filters
    position, effort, v_light, light = raw
    W, y, idx, split, live_w = fitted
    n, dof = position.shape
    rigid = np.zeros(lay.size)  # the fitted rigid body and armature, no friction
    keep = bs.base < lay.rigid + dof
    rigid[bs.base[keep]] = beta[keep]
    _, v, _ = f.motion(position)
    r = np.zeros((n, dof))
    r[idx] = (y - W @ rigid).reshape(len(idx), dof)
    if wide is f:
        v_w, r_w, idx_w = v, r, idx
    else:
        _, v_w, _ = wide.motion(position)
        idx_w = np.arange(2 * wide.window, split, wide.step)
        idx_w = idx_w[live_w[idx_w]]
        W_w = wide.smooth(light)[idx_w].reshape(len(idx_w) * dof, -1)
        r_w = np.zeros((n, dof))
        r_w[idx_w] = wide.effort(effort)[idx_w] - (W_w @ rigid).reshape(-1, dof)
    return [
        turn_speed(
            f, wide, v_light[:, j], (v[:, j], r[:, j], idx), (v_w[:, j], r_w[:, j], idx_w), name
        )
        for j, name in enumerate(lay.joints)
    ]


def _link(body: Body, inertials: dict[str, LinkInertial], margin_m: float) -> Link:
    """The child link's CAD values, its box (see the module) and the other links' parameters."""
    name, pose = body.links[0]
    if not np.allclose(pose, np.eye(4)):
        raise IdentificationError(f"link {name}: its frame is not its joint's")
    cad = inertials[name]
    rest = np.zeros(10)
    for other, other_pose in body.links[1:]:
        li = inertials[other]
        rest += moved(other_pose, li.mass, li.com, li.inertia)
    mass = cad.mass if cad.mass > 0.0 else MASS_FLOOR_KG
    sigma = 0.5 * np.trace(cad.inertia) * np.eye(3) - cad.inertia
    reach = np.sqrt(3.0 * np.maximum(np.diag(sigma), 0.0) / mass) if cad.mass > 0.0 else np.zeros(3)
    points = np.vstack([body.points, cad.com, cad.com - reach, cad.com + reach])
    lo, hi = points.min(axis=0) - margin_m, points.max(axis=0) + margin_m
    floor = 1e-4 * mass * float(np.mean((0.5 * (hi - lo)) ** 2))
    low = float(np.linalg.eigvalsh(sigma)[0])
    if low < floor:  # a CAD inertia that is no body's (a point mass, a placeholder)
        sigma = sigma + (floor - low) * np.eye(3)
    return Link(mass, cad.com.copy(), sigma, lo, hi, rest)


def _joint_scales(
    cad: UrdfModel, x: Arr, estimate: tuple[Arr, Arr], bs: ap.BaseSet, lay: ap.Layout
) -> Arr:
    """What a change of each joint parameter is counted in: its estimate plus three standard
    errors where it is a base parameter, else (an armature carried by a body) the CAD inertia
    the joint moves."""
    beta, std = estimate
    dof = len(lay.joints)
    inertia = np.mean([np.diag(cad.mass_matrix(q)) for q in x[:: max(1, len(x) // 20)]], axis=0)
    out = np.concatenate([inertia, np.ones(2 * dof)])
    for k, column in enumerate(bs.base):
        if column >= lay.rigid:
            out[column - lay.rigid] = abs(beta[k]) + 3.0 * std[k]
    scale: Arr = np.maximum(out, 1e-9)
    return scale


def _check(names: Sequence[str], links: Sequence[Link], found: ConsistentFit) -> None:
    """Physical consistency of every link (see the module); ``IdentificationError`` naming one
    that is not (the parametrisation should make that impossible)."""
    for name, link, (m, c, sigma) in zip(names, links, found.links, strict=True):
        low = float(np.linalg.eigvalsh(pseudo_inertia(m, c, sigma))[0])
        if not (m > 0.0 and low > 0.0 and np.all(c >= link.lo) and np.all(c <= link.hi)):
            raise IdentificationError(
                f"{name}: the fit is not physically consistent (mass {m:.4g} kg, centre of "
                f"mass {np.round(c, 4).tolist()} m, pseudo-inertia eigenvalue {low:.3g})"
            )
