"""Swimming modes of the fish document (docs/algorithms.md §2.7) with numbers from the literature.

Body values are fractions of body length L; fin amplitudes are radians for FLAP,
UP_DOWN and TWIST and, for UNDULATE, the sideways excursion as a fraction of the fin's height.
Amplitudes are CRUISE values (docs/algorithms.md §2.7): a tail peak of
0.06 L is a peak-to-peak of 0.12 L, inside the 0.1-0.13 L of cruising fish (Webb 1975;
Videler 1993, Fish Swimming); Bainbridge's (1958) maximum, about L/5 peak-to-peak
(peak 0.1 L), stays reachable with the Amplitude setting.
"""

import math

# name: (label, description, body settings)
BODY = {
    # Whole-body wave, λ ≈ 0.6 L, amplitude nearly uniform (eel, sea snake).
    # 16 control points: about 10 per wavelength, so the short wave stays smooth.
    "ANGUILLIFORM": {
        "frequency": 1.2,
        "wavelength": 0.6,
        "amplitude": 0.05,
        "amplitude_head": 0.025,
        "envelope_start": 0.0,
        "envelope_power": 1.0,
        "bend": "LATERAL",
        "control_points": 16,
    },
    # Rear third of the body plus caudal fin, λ ≈ 1 L, cruise tail peak 0.06 L (jack, mackerel).
    "CARANGIFORM": {
        "frequency": 2.0,
        "wavelength": 1.0,
        "amplitude": 0.06,
        "amplitude_head": 0.006,
        "envelope_start": 0.45,
        "envelope_power": 1.6,
        "bend": "LATERAL",
        "control_points": 8,
    },
    # Stiff body: peduncle and tail only (tuna).
    "THUNNIFORM": {
        "frequency": 2.5,
        "wavelength": 1.25,
        "amplitude": 0.055,
        "amplitude_head": 0.003,
        "envelope_start": 0.6,
        "envelope_power": 2.2,
        "bend": "LATERAL",
        "control_points": 8,
    },
    # Rigid body, caudal fin only (boxfish): the body wave is off; the caudal fin flaps.
    "OSTRACIIFORM": {
        "frequency": 2.0,
        "wavelength": 1.0,
        "amplitude": 0.0,
        "amplitude_head": 0.0,
        "envelope_start": 0.8,
        "envelope_power": 1.0,
        "bend": "LATERAL",
        "control_points": 8,
    },
    # Body still, dorsal and anal fins undulate (filefish, triggerfish).
    "BALISTIFORM": {
        "frequency": 2.0,
        "wavelength": 1.0,
        "amplitude": 0.0,
        "amplitude_head": 0.0,
        "envelope_start": 0.8,
        "envelope_power": 1.0,
        "bend": "LATERAL",
        "control_points": 8,
    },
    # Body still, pectoral fins row (wrasse, porcupinefish).
    "LABRIFORM": {
        "frequency": 1.5,
        "wavelength": 1.0,
        "amplitude": 0.0,
        "amplitude_head": 0.0,
        "envelope_start": 0.8,
        "envelope_power": 1.0,
        "bend": "LATERAL",
        "control_points": 8,
    },
    # Thunniform in the dorsoventral plane (dolphin, whale).
    "CETACEAN": {
        "frequency": 1.5,
        "wavelength": 1.25,
        "amplitude": 0.06,
        "amplitude_head": 0.006,
        "envelope_start": 0.5,
        "envelope_power": 2.0,
        "bend": "DORSOVENTRAL",
        "control_points": 8,
    },
}

LABELS = {
    "ANGUILLIFORM": ("Anguilliform", "Whole-body wave, wavelength about 0.6 body lengths (eel)"),
    "CARANGIFORM": (
        "Carangiform",
        "Rear third of the body and the tail, wavelength about 1 body length",
    ),
    "THUNNIFORM": ("Thunniform", "Stiff body; peduncle and tail only (tuna)"),
    "OSTRACIIFORM": ("Ostraciiform", "Rigid body; only the caudal fin moves (boxfish)"),
    "BALISTIFORM": ("Balistiform", "Body still; dorsal and anal fins undulate (filefish)"),
    "LABRIFORM": ("Labriform", "Body still; pectoral fins row (pufferfish, wrasse)"),
    "CETACEAN": ("Cetacean", "Thunniform in the dorsoventral plane (dolphin)"),
}

ORDER = (
    "ANGUILLIFORM",
    "CARANGIFORM",
    "THUNNIFORM",
    "OSTRACIIFORM",
    "BALISTIFORM",
    "LABRIFORM",
    "CETACEAN",
)

FIN_KINDS = ("PECTORAL", "DORSAL", "ANAL", "CAUDAL", "PELVIC")
FIN_MOTIONS = ("FLAP", "UP_DOWN", "TWIST", "UNDULATE")

# Default motion of a fin of each kind.
FIN_MOTION_BY_KIND = {
    "PECTORAL": "FLAP",
    "DORSAL": "UNDULATE",
    "ANAL": "UNDULATE",
    "CAUDAL": "FLAP",
    "PELVIC": "UP_DOWN",
}

_DEG = math.pi / 180.0

# (preset, kind) -> (amplitude, phase lag radians, feathering radians); unlisted → small beat.
FIN_BY_PRESET = {
    ("ANGUILLIFORM", "DORSAL"): (0.2, 0.0, 0.0),
    ("ANGUILLIFORM", "ANAL"): (0.2, 0.0, 0.0),
    ("ANGUILLIFORM", "CAUDAL"): (0.0, 0.0, 0.0),
    ("CARANGIFORM", "PECTORAL"): (15 * _DEG, 90 * _DEG, 30 * _DEG),
    ("CARANGIFORM", "CAUDAL"): (0.0, 0.0, 0.0),
    ("CARANGIFORM", "DORSAL"): (0.1, 0.0, 0.0),
    ("CARANGIFORM", "ANAL"): (0.1, 0.0, 0.0),
    ("THUNNIFORM", "PECTORAL"): (5 * _DEG, 90 * _DEG, 0.0),
    ("THUNNIFORM", "CAUDAL"): (10 * _DEG, 90 * _DEG, 0.0),
    ("THUNNIFORM", "DORSAL"): (0.0, 0.0, 0.0),
    ("THUNNIFORM", "ANAL"): (0.0, 0.0, 0.0),
    ("OSTRACIIFORM", "CAUDAL"): (30 * _DEG, 0.0, 0.0),
    ("OSTRACIIFORM", "PECTORAL"): (35 * _DEG, 90 * _DEG, 60 * _DEG),
    ("OSTRACIIFORM", "DORSAL"): (0.0, 0.0, 0.0),
    ("OSTRACIIFORM", "ANAL"): (0.0, 0.0, 0.0),
    ("BALISTIFORM", "DORSAL"): (0.35, 0.0, 0.0),
    ("BALISTIFORM", "ANAL"): (0.35, math.pi, 0.0),
    ("BALISTIFORM", "PECTORAL"): (15 * _DEG, 90 * _DEG, 30 * _DEG),
    ("BALISTIFORM", "CAUDAL"): (5 * _DEG, 0.0, 0.0),
    ("LABRIFORM", "PECTORAL"): (45 * _DEG, 0.0, 80 * _DEG),
    ("LABRIFORM", "CAUDAL"): (5 * _DEG, 0.0, 0.0),
    ("LABRIFORM", "DORSAL"): (0.15, 0.0, 0.0),
    ("LABRIFORM", "ANAL"): (0.15, 0.0, 0.0),
    ("CETACEAN", "PECTORAL"): (8 * _DEG, 90 * _DEG, 0.0),
    ("CETACEAN", "CAUDAL"): (0.0, 0.0, 0.0),
    ("CETACEAN", "DORSAL"): (0.0, 0.0, 0.0),
}


def fin_defaults(preset, kind):
    """(motion, amplitude, phase_lag, feathering) of a new fin of `kind` under `preset`."""
    motion = FIN_MOTION_BY_KIND[kind]
    amplitude, lag, feathering = FIN_BY_PRESET.get(
        (preset, kind), (10 * _DEG if motion != "UNDULATE" else 0.3, 0.0, 0.0)
    )
    return motion, amplitude, lag, feathering


def apply_body(settings, preset):
    """Write a preset's body values into the settings (the user tunes from there)."""
    for name, value in BODY[preset].items():
        setattr(settings, name, value)


def apply_fins(settings, preset):
    for fin in settings.fins:
        motion, amplitude, lag, feathering = fin_defaults(preset, fin.kind)
        fin.motion = motion
        fin.amplitude = amplitude
        fin.phase_lag = lag
        fin.feathering = feathering
