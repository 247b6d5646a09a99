"""MuJoCo rig: the same pin passage in an independent physics engine.

It shares no code with the kernels: mass properties, the support grid, the
triangulation of a non-convex outline and the pin path are computed here with
NumPy, the dynamics and the pin contact are MuJoCo's. Use it to cross-check
the dynamic model or a plan; it is far too slow for maps (seconds a passage).

Notes
-----
Set-up, in SI units, in the belt frame (belt at rest, pin moving):

- the part is a prism (thickness 4 mm) of mesh pieces, one per triangle of an
  ear-clipping triangulation (MuJoCo collides with the convex hull of a mesh,
  so a non-convex outline must be split), on a planar joint set (slide x,
  slide y, hinge z) through its centroid, with the mass and polar inertia of
  the uniform material and no gravity;
- a part with holes: the mass properties are the material's (the outline's
  shoelace sums less each hole's: area, centroid, polar inertia about the
  material's centroid) and the support grid leaves the holes out, but the
  collision prism is the outline's, holes filled: the pin comes from the
  belt's edge side and touches the outline only (it cannot enter a closed
  hole), so the pieces, the pin path, the feature book-keeping and the
  passage's end test all take the outline alone, and a hole changes nothing
  the pin can touch; the ``inertial`` element sets mass and inertia, so the
  filled prism does not put mass into a hole (``inertiafromgeom`` is off);
- belt friction is applied by hand as generalised forces: support points on a
  2.5 mm grid on the material (inside the outline and in no hole; about 150
  for a 40-60 mm part), each loaded ``mu_s m g / K``, force
  ``-N u / sqrt(|u|^2 + eps^2)`` with ``u`` the point's velocity and
  ``eps = 0.2 mm/s`` (MuJoCo's own floor contacts lift off while sliding in
  its soft contact model);
- the pin is a sphere of radius ``r_pin`` at the prism's mid-plane (a cylinder
  against a mesh gives wrong normals at vertices) on a heavy body (1e5 kg) on
  a slide joint along the pin's path; its joint velocity is reset to the pin
  speed every step (a mocap pin has zero velocity in the contact solver, so
  pin friction would oppose the part's absolute motion);
- timestep 5e-5 s, elliptic friction cones, impratio 10, solref (0.004, 1),
  contact friction ``mu_c`` (frictionless contact for ``mu_c = 0``).

What the rig models for a part with holes, in short: the material's mass,
centroid (the body's origin and the joints' axis) and polar inertia; belt
friction only under material (the grid's points in a hole are dropped, the
rest share ``mu_s m g`` evenly); the pin against the outline's prism only.
It does not model a pin inside a hole (a hole is closed, the pin comes from
outside), a hole's effect on the part's thickness or stiffness, or pressure
that is not uniform over the material (a point ``support`` replaces the grid).
The grid is the rig's main error against the kernels, solid or holed: on the
pushes of ``benchmarks/mujoco_holes.py`` the worst |delta theta_f| against
the quasi-static kernel at 50 mm/s is 0.3 to 4.6 deg at 2.5 mm and 0.1 to
0.7 deg at 0.8 mm, and the same rig with the holes filled stays off by about
what the holes move the answer (docs/explanation/fast-belts.md).

A passage ends when the part is out of contact, every support point moves
slower than ``_REST`` times the belt speed, and the pin's remaining path
misses the part. Jams: no rotation (< 1e-4 rad over 3 a of pin travel in
contact), two contacts more than 1e-3 a apart (notch), pin travel in contact
past 50 a. The peak force leaves out the first 10 ms of each contact episode
(the impact, whose peak depends on the contact stiffness).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pipeline.errors import PinfeedError

THICKNESS_MM = 4.0
GRID_MM = 2.5
V_REG_MM_S = 0.2
TIMESTEP = 5e-5
SOLREF = (0.004, 1.0)
IMPRATIO = 10.0
PIN_MASS = 1e5
PART_MASS = 0.01  # kg; the kinematics do not depend on it
G = 9.81
_REST = 2e-3  # fraction of the belt speed
_IMPACT_S = 0.01


def _mujoco():
    try:
        import mujoco
    except ImportError:
        raise PinfeedError("--model mujoco needs the 'mujoco' Python package: pip install mujoco") \
            from None
    return mujoco


def _mass_properties(xy):
    """Area, centroid and polar second moment about the centroid (shoelace)."""
    x, y = xy[:, 0], xy[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cr = x * yn - xn * y
    area = 0.5 * cr.sum()
    cx = ((x + xn) * cr).sum() / (6.0 * area)
    cy = ((y + yn) * cr).sum() / (6.0 * area)
    jo = (cr * (x * x + x * xn + xn * xn + y * y + y * yn + yn * yn)).sum() / 12.0
    j = jo - area * (cx * cx + cy * cy)
    return area, np.array([cx, cy]), j


def _material_properties(outline, holes=()):
    """Area, centroid and polar second moment about the centroid of the
    material: the outline (counter-clockwise) less the holes, each hole's
    shoelace sums taken with the opposite sign (any winding given). A solid
    part: :func:`_mass_properties` of the outline, to the bit."""
    if not len(holes):
        return _mass_properties(np.asarray(outline, dtype=float))
    area = jo = 0.0
    first = np.zeros(2)
    for k, loop in enumerate([outline, *holes]):
        a_k, c_k, j_k = _mass_properties(np.asarray(loop, dtype=float))
        sign = (1.0 if a_k > 0 else -1.0) * (1.0 if k == 0 else -1.0)
        a_k = sign * a_k  # signed area of the loop as material (+) or hole (-)
        area += a_k
        first += a_k * c_k
        jo += sign * j_k + a_k * float(c_k @ c_k)  # parallel axes: about the origin
    com = first / area
    return area, com, jo - area * float(com @ com)


def _inside(xy, pts):
    """Even-odd point-in-polygon test."""
    x, y = pts[:, 0][:, None], pts[:, 1][:, None]
    x0, y0 = xy[:, 0][None, :], xy[:, 1][None, :]
    x1, y1 = np.roll(xy[:, 0], -1)[None, :], np.roll(xy[:, 1], -1)[None, :]
    cond = (y0 > y) != (y1 > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
    return (cond & (x < xc)).sum(axis=1) % 2 == 1


def _triangulate(xy):
    """Ear clipping of a counter-clockwise simple polygon: list of index triples."""
    idx = list(range(len(xy)))
    tris = []

    def cross(o, a, b):
        return (xy[a, 0] - xy[o, 0]) * (xy[b, 1] - xy[o, 1]) - (xy[a, 1] - xy[o, 1]) * (xy[b, 0] - xy[o, 0])

    guard = 0
    while len(idx) > 3 and guard < 10000:
        guard += 1
        n = len(idx)
        for k in range(n):
            i, j, m = idx[k - 1], idx[k], idx[(k + 1) % n]
            if cross(i, j, m) <= 0:
                continue
            ok = True
            for p in idx:
                if p in (i, j, m):
                    continue
                if cross(i, j, p) >= 0 and cross(j, m, p) >= 0 and cross(m, i, p) >= 0:
                    ok = False
                    break
            if ok:
                tris.append((i, j, m))
                idx.pop(k)
                break
    tris.append(tuple(idx))
    return tris


def _seg_dist(p, q, a, b):
    """Distance between segments pq and ab (2-D)."""
    def pt_seg(x, u, v):
        d = v - u
        t = np.clip(np.dot(x - u, d) / max(np.dot(d, d), 1e-300), 0.0, 1.0)
        return np.linalg.norm(x - (u + t * d))

    def cr(o, u, v):
        return (u[0] - o[0]) * (v[1] - o[1]) - (u[1] - o[1]) * (v[0] - o[0])

    d1, d2, d3, d4 = cr(a, b, p), cr(a, b, q), cr(p, q, a), cr(p, q, b)
    if (d1 > 0) != (d2 > 0) and (d3 > 0) != (d4 > 0) and d1 * d2 < 0 and d3 * d4 < 0:
        return 0.0
    return min(pt_seg(p, a, b), pt_seg(q, a, b), pt_seg(a, p, q), pt_seg(b, p, q))


def _path_hits(world_xy, start, direction, length, r_pin):
    """Does a disc of radius ``r_pin`` moving from ``start`` along ``direction``
    (unit) for ``length`` touch the polygon ``world_xy``?"""
    end = start + length * direction
    n = len(world_xy)
    for j in range(n):
        if _seg_dist(start, end, world_xy[j], world_xy[(j + 1) % n]) <= r_pin:
            return True
    return bool(_inside(world_xy, start[None, :])[0])


def _first_touch(world_xy, start, direction, length, r_pin):
    """Travel along the path to the first touch (bisection on the swept test)."""
    if not _path_hits(world_xy, start, direction, length, r_pin):
        return math.inf
    lo, hi = 0.0, length
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if _path_hits(world_xy, start, direction, mid, r_pin):
            hi = mid
        else:
            lo = mid
    return lo


def _model_xml(pieces, r_pin, mu_c, mass, izz, pin_start, pin_dir, timestep=TIMESTEP):
    t = THICKNESS_MM / 1000.0
    meshes, geoms = [], []
    for k, tri in enumerate(pieces):
        verts = []
        for x, y in tri:
            verts += [f"{x:.9g} {y:.9g} {-t / 2:.9g}", f"{x:.9g} {y:.9g} {t / 2:.9g}"]
        meshes.append(f'<mesh name="piece{k}" vertex="{" ".join(verts)}"/>')
        geoms.append(f'<geom type="mesh" mesh="piece{k}" contype="1" conaffinity="2" '
                     f'condim="{3 if mu_c > 0 else 1}" friction="{mu_c:.9g} 0 0" '
                     f'solref="{SOLREF[0]} {SOLREF[1]}"/>')
    return f"""
<mujoco model="pinfeed-rig">
  <compiler inertiafromgeom="false" angle="radian"/>
  <option timestep="{timestep:.9g}" gravity="0 0 0" cone="elliptic" impratio="{IMPRATIO}"
          integrator="Euler"/>
  <asset>{''.join(meshes)}</asset>
  <worldbody>
    <body name="part" pos="0 0 0">
      <joint name="px" type="slide" axis="1 0 0" damping="0"/>
      <joint name="py" type="slide" axis="0 1 0" damping="0"/>
      <joint name="pth" type="hinge" axis="0 0 1" damping="0"/>
      <inertial pos="0 0 0" mass="{mass:.9g}" diaginertia="{izz:.9g} {izz:.9g} {izz:.9g}"/>
      {''.join(geoms)}
    </body>
    <body name="pin" pos="{pin_start[0]:.9g} {pin_start[1]:.9g} 0">
      <joint name="pin" type="slide" axis="{pin_dir[0]:.9g} {pin_dir[1]:.9g} 0"/>
      <inertial pos="0 0 0" mass="{PIN_MASS}" diaginertia="1 1 1"/>
      <geom name="pin" type="sphere" size="{r_pin:.9g}" contype="2" conaffinity="1"
            condim="{3 if mu_c > 0 else 1}" friction="{mu_c:.9g} 0 0"
            solref="{SOLREF[0]} {SOLREF[1]}"/>
    </body>
  </worldbody>
</mujoco>"""


def mujoco_rollout(part, theta_i_deg, d, mu_c, r_pin_mm, belt_speed_mm_s, mu_s=0.5, v_pin=0.0,
                   max_travel=math.inf, trajectory=False, record_every=40,
                   mass=PART_MASS, support=None):
    """One passage in MuJoCo. Lengths in mm, speeds in mm/s, angles in degrees;
    ``support``: a checked point support (its points carry the belt friction
    by weight) or ``None`` (a grid over the area: uniform).

    Returns ``(status, jam_reason, theta_f_rad, dy_mm, contact_travel_mm,
    feature_changes, peak_force, trajectory, force)`` with status codes
    0 ok, 1 miss, 2 jammed, 3 truncated (as the kernels); ``trajectory``
    rows ``(s, x, y, theta_rad)`` and ``force`` rows ``(s, F_x, F_y)`` (force
    on the pin, units of mu_s m g; s = belt travel since first contact, mm)."""
    mujoco = _mujoco()
    xy, a, izz, pts, load = _support(part, mass, mu_s, support)
    r_pin = r_pin_mm / 1000.0
    vb = belt_speed_mm_s / 1000.0
    eps = V_REG_MM_S / 1000.0
    th0 = math.radians(theta_i_deg)
    direction, speed, start, touch = _pin_path(xy, th0, d, v_pin, a, r_pin)
    if not math.isfinite(touch):
        return 1, "none", th0 % (2 * math.pi), 0.0, 0.0, 0, 0.0, np.zeros((0, 4)), np.zeros((0, 3))
    pin_start = start + max(touch - 0.02e-3, 0.0) * direction
    model, data = _build(mujoco, xy, r_pin, mu_c, mass, izz, pin_start, direction, th0,
                         _timestep(pts, load, izz, mass, mu_s))
    pin_dof = model.jnt_dofadr[model.joint("pin").id]
    pin_geom = model.geom("pin").id
    dt = model.opt.timestep
    pin_speed = vb * speed
    forces6 = np.zeros(6)
    st = _Passage(theta_ref=th0)
    max_steps = int((60.0 * a * speed + 10 * a) / (vb * dt)) + 200000
    while True:
        st.step += 1
        if st.step > max_steps:
            st.status, st.reason = 3, "step budget"
            break
        data.qvel[pin_dof] = pin_speed
        ux, uy = _apply_belt_friction(data, pts, load, eps)
        mujoco.mj_step(model, data)
        st.s_belt += vb * dt
        fpx, fpy, touching, where = _pin_contacts(mujoco, model, data, pin_geom, forces6)
        if touching and _contact_step(st, model, data, xy, a, vb * dt, dt,
                                      math.hypot(fpx, fpy) / (mu_s * mass * G), where):
            break
        st.was_touching = touching
        if trajectory and st.step % record_every == 0:
            st.traj.append((st.s_belt * 1000.0, data.qpos[0] * 1000.0, data.qpos[1] * 1000.0,
                            data.qpos[2]))
            st.frc.append((st.s_belt * 1000.0, fpx / (mu_s * mass * G), fpy / (mu_s * mass * G)))
        if st.s_belt * 1000.0 >= max_travel:
            st.status, st.reason = 3, "none"
            break
        if not touching and st.step % 20 == 0 and _passage_over(model, data, xy, ux, uy, vb,
                                                                direction, a, r_pin):
            break
    if st.status == 0 and st.travel == 0.0:
        st.status = 1
    return (st.status, st.reason, float(data.qpos[2]) % (2 * math.pi), float(data.qpos[1]) * 1000.0,
            st.travel * 1000.0, st.changes, st.peak, np.array(st.traj).reshape(-1, 4),
            np.array(st.frc).reshape(-1, 3))


def _timestep(pts, load, izz, mass, mu_s) -> float:
    """The step: ``TIMESTEP``, shortened for a support whose friction moment of
    inertia ``sum load_k r_k^2 / (mu_s g)`` exceeds the part's (``izz / mass``
    per unit mass). Near rest the regularised belt friction is a viscous
    damping of rate ``load r^2 / (eps I)``; explicit Euler with that rate
    times the step above 2 oscillates about rest for ever (points at the
    vertices of a triangle reach 4). Uniform pressure keeps ``TIMESTEP``."""
    if np.ndim(load) == 0:
        return TIMESTEP
    ratio = float(np.sum(load * np.sum(pts * pts, axis=1)) / (mu_s * mass * G) / (izz / mass))
    return TIMESTEP / max(1, math.ceil(ratio))


def _build(mujoco, xy, r_pin, mu_c, mass, izz, pin_start, direction, th0, timestep=TIMESTEP):
    """The MuJoCo model (a non-convex outline split into triangles) and its data
    with the part at orientation ``th0`` (rad)."""
    pieces = [xy[list(t)] for t in _triangulate(xy)] if not _convex(xy) else [xy]
    model = mujoco.MjModel.from_xml_string(_model_xml(pieces, r_pin, mu_c, mass, izz, pin_start,
                                                      direction, timestep))
    data = mujoco.MjData(model)
    data.qpos[2] = th0
    return model, data


@dataclass
class _Passage:
    """The running state of one MuJoCo passage (SI units; ``s_belt`` belt travel)."""
    theta_ref: float
    travel: float = 0.0
    s_belt: float = 0.0
    changes: int = 0
    peak: float = 0.0
    feature: tuple | None = None
    episode_t: float = 0.0
    was_touching: bool = False
    travel_ref: float = 0.0
    status: int = 0
    reason: str = "none"
    step: int = 0
    traj: list = field(default_factory=list)
    frc: list = field(default_factory=list)


def _support(part, mass, mu_s, support=None):
    """``(xy, a, izz, pts, load)``: the outline about the material's centroid
    (m), its radius a (m), the material's polar inertia (kg m^2), the support
    points (m, body frame: a grid on the material, or the points of
    ``support``) and the belt's friction load on each (N: ``mu_s m g``
    shared evenly, or by weight). Holes (``part.holes``) take out area,
    inertia and grid points; the outline stays whole (module notes)."""
    xy_mm = np.asarray(part.vertices, dtype=float)
    if _mass_properties(xy_mm)[0] < 0:
        xy_mm = xy_mm[::-1].copy()
    holes_mm = [np.asarray(h, dtype=float) for h in getattr(part, "holes", ())]
    area, com, jpol = _material_properties(xy_mm, holes_mm)
    xy_mm = xy_mm - com
    holes = [(h - com) / 1000.0 for h in holes_mm]
    a_mm = float(np.max(np.hypot(xy_mm[:, 0], xy_mm[:, 1])))
    xy = xy_mm / 1000.0
    a = a_mm / 1000.0
    izz = mass * jpol / area / 1e6
    if support is not None:  # the same points as the kernels (part frame, centroid at the origin)
        pts = (np.asarray(support.points, dtype=float) - com) / 1000.0
        return xy, a, izz, pts, mu_s * mass * G * np.asarray(support.weights, dtype=float)
    # Support grid (body frame), centred on the centroid.
    s = GRID_MM / 1000.0
    span = np.arange(-math.ceil(a / s), math.ceil(a / s) + 1) * s
    gx, gy = np.meshgrid(span, span)
    pts = np.column_stack([gx.ravel(), gy.ravel()])
    keep = _inside(xy, pts)
    for hole in holes:
        keep &= ~_inside(hole, pts)
    pts = pts[keep]
    load = mu_s * mass * G / len(pts)
    return xy, a, izz, pts, load


def _pin_path(xy, th0, d, v_pin, a, r_pin):
    """``(direction, speed, start, touch)`` of the pin's straight path in the
    belt frame, ``P(tau) = (-tau, d a + v_pin tau)`` scaled by the belt speed:
    unit direction, speed over belt speed, start point (m) and the distance
    (m) along the path to first touch (``inf`` for a miss)."""
    rot = np.array([[math.cos(th0), -math.sin(th0)], [math.sin(th0), math.cos(th0)]])
    world = xy @ rot.T
    vel = np.array([-1.0, v_pin])
    speed = float(np.linalg.norm(vel))
    direction = vel / speed
    tau0 = -(2.0 + r_pin / a + abs(d)) * (1.0 + abs(v_pin)) * a
    start = np.array([-tau0, d * a + v_pin * tau0])
    reach = 2.0 * abs(tau0) * speed
    touch = _first_touch(world, start, direction, reach, r_pin)
    return direction, speed, start, touch


def _apply_belt_friction(data, pts, load, eps):
    """Set the belt's regularised friction on the part as generalised forces;
    returns the support points' velocities ``(ux, uy)`` (m/s)."""
    th = data.qpos[2]
    c, sn = math.cos(th), math.sin(th)
    rx = c * pts[:, 0] - sn * pts[:, 1]
    ry = sn * pts[:, 0] + c * pts[:, 1]
    vx, vy, om = data.qvel[0], data.qvel[1], data.qvel[2]
    ux = vx - om * ry
    uy = vy + om * rx
    k = load / np.sqrt(ux * ux + uy * uy + eps * eps)
    fx = -k * ux
    fy = -k * uy
    data.qfrc_applied[0] = fx.sum()
    data.qfrc_applied[1] = fy.sum()
    data.qfrc_applied[2] = (rx * fy - ry * fx).sum()
    return ux, uy


def _pin_contacts(mujoco, model, data, pin_geom, forces6):
    """``(fpx, fpy, touching, where)``: the force on the pin (N), whether it
    pushes, and the contact points (m)."""
    fpx = fpy = 0.0
    touching = False
    where = []
    for i in range(data.ncon):
        con = data.contact[i]
        if pin_geom not in (con.geom1, con.geom2):
            continue
        mujoco.mj_contactForce(model, data, i, forces6)
        if forces6[0] <= 0.0:
            continue
        touching = True
        frame = np.array(con.frame).reshape(3, 3)
        f_world = frame.T @ forces6[:3]
        sign = 1.0 if con.geom2 == pin_geom else -1.0  # force on geom2 is +f
        fpx += sign * f_world[0]
        fpy += sign * f_world[1]
        where.append(np.array(con.pos[:2]))
    return fpx, fpy, touching, where


def _contact_step(st, model, data, xy, a, ds, dt, f, where) -> bool:
    """Book one step in contact (``ds`` pin travel, m; ``f`` force on the pin
    in mu_s m g): peak force, feature changes, jams. True when jammed."""
    if not st.was_touching:
        st.episode_t = 0.0
    st.episode_t += dt
    st.travel += ds
    if st.episode_t > _IMPACT_S:
        st.peak = max(st.peak, f)
    if len(where) > 1:
        spread = max(np.linalg.norm(w - where[0]) for w in where)
        if spread > 1e-3 * a:
            st.status, st.reason = 2, "notch"
            return True
    if st.step % 20 == 0:
        feat = _feature(xy, data.qpos[:3], data.xpos[model.body("pin").id][:2])
        if st.feature is not None and feat != st.feature:
            st.changes += 1
        st.feature = feat
    th = data.qpos[2]
    if abs(th - st.theta_ref) >= 1e-4:
        st.theta_ref, st.travel_ref = th, st.travel
    elif st.travel - st.travel_ref > 3.0 * a:
        st.status, st.reason = 2, "no rotation"
        return True
    if st.travel > 50.0 * a:
        st.status, st.reason = 2, "travel limit"
        return True
    return False


def _passage_over(model, data, xy, ux, uy, vb, direction, a, r_pin) -> bool:
    """Whether the part (out of contact) is at rest on the belt and the pin's
    remaining path misses it."""
    vmax = float(np.sqrt((ux * ux + uy * uy).max()))
    if vmax < _REST * vb:
        th = data.qpos[2]
        rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
        world = xy @ rot.T + data.qpos[:2]
        pin_now = np.array(data.xpos[model.body("pin").id][:2])
        if not _path_hits(world, pin_now + 1e-6 * direction, direction,
                          4.0 * a + 2.0 * r_pin, r_pin * 0.999):
            return True
    return False


def _convex(xy):
    e = np.roll(xy, -1, axis=0) - xy
    cr = e[:, 0] * np.roll(e[:, 1], -1) - e[:, 1] * np.roll(e[:, 0], -1)
    return bool(np.all(cr >= 0))


def _feature(xy, qpos, pin):
    """Nearest boundary feature (edge j or vertex j) to the pin, body frame."""
    th = qpos[2]
    c, s = math.cos(th), math.sin(th)
    p = np.array([c * (pin[0] - qpos[0]) + s * (pin[1] - qpos[1]),
                  -s * (pin[0] - qpos[0]) + c * (pin[1] - qpos[1])])
    a = xy
    b = np.roll(xy, -1, axis=0)
    d = b - a
    t = np.clip(((p - a) * d).sum(1) / (d * d).sum(1), 0.0, 1.0)
    dist = np.hypot(*(a + t[:, None] * d - p).T)
    j = int(np.argmin(dist))
    if t[j] <= 1e-3:
        return ("v", j)
    if t[j] >= 1 - 1e-3:
        return ("v", (j + 1) % len(xy))
    return ("e", j)
