"""Colour conversions between linear render data and display-referred files."""
import numpy as np


def linear_to_srgb(linear):
    """Linear Rec.709 values -> sRGB-encoded values in [0, 1] (IEC 61966-2-1).

    For writing linear render passes to 8-bit PNG: values are clipped to
    [0, 1] first (no tone mapping) and NaN becomes 0. Returns float32.
    """
    x = np.nan_to_num(np.asarray(linear, dtype=np.float64), nan=0.0, posinf=1.0, neginf=0.0)
    x = np.clip(x, 0.0, 1.0)
    low = x * 12.92
    high = 1.055 * np.power(x, 1.0 / 2.4) - 0.055
    return np.where(x <= 0.0031308, low, high).astype(np.float32)


def srgb_to_linear(encoded):
    """Inverse of linear_to_srgb for values in [0, 1] (e.g. colours read from PNG)."""
    x = np.clip(np.asarray(encoded, dtype=np.float64), 0.0, 1.0)
    low = x / 12.92
    high = np.power((x + 0.055) / 1.055, 2.4)
    return np.where(x <= 0.04045, low, high).astype(np.float32)
