"""Axis labels in the case's units.

A case is in SI units when it says so ([case] units = SI, if the key exists)
or when any of its gravity keys (physics.gravity, bedload.gravity,
duct.gravity, ...) is Earth's, 9.81 m/s^2; else it is dimensionless in the
scales its scene is written in (the grain diameter d and g for the granular
layers, H0 for the collapse, the cavity's side and lid speed, ...):
labels then read "z / d", or the bare symbol where the scene has no named
scale."""

SI = {"length": "m", "velocity": "m/s", "time": "s", "pressure": "Pa", "rate": "1/s",
      "viscosity": "Pa s", "none": ""}


def _scaled(length, velocity, time, pressure, rate, viscosity):
    return {"length": length, "velocity": velocity, "time": time, "pressure": pressure,
            "rate": rate, "viscosity": viscosity, "none": ""}


GRAIN = _scaled("d", r"$\sqrt{g d}$", r"$\sqrt{d/g}$", r"$\rho g d$", r"$\sqrt{g/d}$",
                r"$\rho d \sqrt{g d}$")
COLUMN = _scaled("H$_0$", r"$\sqrt{g H_0}$", r"$\sqrt{H_0/g}$", r"$\rho g H_0$",
                 r"$\sqrt{g/H_0}$", r"$\rho H_0 \sqrt{g H_0}$")
CHANNEL = _scaled("H", "U", "H/U", r"$\mu U/H$", "U/H", r"$\mu$")
CAVITY = _scaled("L", "U", "L/U", r"$\mu_p U/L$", "U/L", r"$\mu_p$")
CYLINDER = _scaled("D", "", "", "", "", "")
NONE = _scaled("", "", "", "", "", "")

SCENE_SCALES = {"bagnold": GRAIN, "chute": GRAIN, "heap": GRAIN, "collapse": COLUMN,
                "couette": CHANNEL, "bingham_channel": CHANNEL, "bingham_cavity": CAVITY,
                "cylinder": CYLINDER}


def is_si(run):
    stated = run.key("case.units")
    if stated is not None:
        return stated.strip().lower() == "si"
    for k in run.case:
        if k.endswith(".gravity") and abs(run.num(k) - 9.81) < 0.02:
            return True
    return False


class Units:
    def __init__(self, run):
        self.si = is_si(run)
        self.table = SI if self.si else SCENE_SCALES.get(run.scene, NONE)

    def unit(self, kind):
        return self.table.get(kind, "")

    def label(self, symbol, kind):
        """'z [m]' in SI, 'z / d' in a named scale, 'z' without one."""
        u = self.unit(kind)
        if not u:
            return symbol
        if self.si:
            return "%s [%s]" % (symbol, u)
        if " - " in symbol or " + " in symbol:
            symbol = "(%s)" % symbol
        return "%s / %s" % (symbol, u)


# the kind of quantity each field-file dataset holds
FIELD_KIND = {"velocity": "velocity", "u": "velocity", "v": "velocity", "w": "velocity",
              "particle_velocity": "velocity", "up": "velocity", "vp": "velocity",
              "wp": "velocity", "pressure": "pressure", "pressure_regularised": "pressure",
              "shear_rate": "rate", "viscosity": "viscosity"}
