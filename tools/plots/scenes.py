"""compare.png: the scene's own comparison with its reference, and the
[result] keys each scene's headline prints.  A scene not named here (a new
one) is drawn from what its outputs hold: its profile.csv against the exact
column there, if any (profile.py), in the case's units or none."""
from . import cavity, collapse, cylinder, duct, heap, profile

COMPARE = {
    "bagnold": profile.plot, "bagnold2": profile.plot, "chute": profile.plot,
    "couette": profile.plot, "bingham_channel": profile.plot, "bedload": profile.plot,
    "bingham_cavity": cavity.plot, "heap": heap.plot, "duct": duct.plot,
    "collapse": collapse.plot, "cylinder": cylinder.plot_drag,
}

# [result] keys worth a line beside status, steps and the errors
HEADLINE = {
    "heap": ("tilt", "flow_rate", "u_surface_mid", "depth_mid"),
    "collapse": ("time", "x_front", "h_axis", "x_front_err_max", "h_axis_err_max",
                 "mass_error"),
    "cylinder": ("forcing", "drag", "drag_surface", "froude"),
    "duct": ("velocity_ratio",),
    "bagnold2": ("err_rms_grains", "err_rms_air"),
    "bedload": ("err_rms_particles",),
}
BODY_HEADLINE = ("drag_coefficient", "lift_coefficient", "pressure_drop")


def comparison(run):
    """The function drawing the run's compare.png, or None."""
    if run.scene in COMPARE:
        return COMPARE[run.scene]
    if "drag_coefficient" in run.result:  # a body in a channel (scene none)
        return cylinder.plot_benchmark
    if run.table("profile.csv") is not None:
        return profile.plot
    return None


def headline(run):
    """(key, text) lines of [result]: status, steps, the error, each value
    that has an exact, reference or plane-channel partner, and the scene's
    own keys; each key once, in that order."""
    res = run.result
    keys = ["status", "steps"]
    keys += ["err_rms", "err_midline", "diff_plane"]
    keys += [k for k in res if run.partner(k)]
    keys += list(HEADLINE.get(run.scene, ()))
    if run.scene not in COMPARE:
        keys += list(BODY_HEADLINE)
    lines, seen = [], set()
    for k in keys:
        if k in seen or k not in res:
            continue
        seen.add(k)
        p = run.partner(k)
        lines.append((k, res[k] + (" (%s %s)" % p if p else "")))
    return lines
