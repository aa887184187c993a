"""The G- and M-codes the interpreter knows: their modal groups, and why well-known codes
it does not implement are refused (the error names the feature)."""

from __future__ import annotations

# G codes are held as int(round(10 * value)): G1 -> 10, G90.1 -> 901.
G_GROUP = {
    40: 0, 100: 0, 520: 0, 280: 0, 281: 0, 300: 0, 301: 0, 530: 0, 920: 0, 921: 0, 922: 0, 923: 0,
    0: 1, 10: 1, 20: 1, 30: 1, 50: 1, 51: 1, 52: 1, 53: 1, 330: 1, 331: 1, 760: 1, 800: 1, 730: 1,
    740: 1, 810: 1, 820: 1,
    830: 1, 840: 1, 850: 1, 860: 1, 870: 1, 880: 1, 890: 1, 382: 1, 383: 1, 384: 1, 385: 1,
    700: 1, 710: 1, 711: 1, 712: 1, 720: 1, 721: 1, 722: 1,  # lathe cycles (latheprofile.py)
    170: 2, 180: 2, 190: 2,
    900: 3, 910: 3,
    901: 4, 911: 4,
    930: 5, 940: 5, 950: 5,
    960: 14, 970: 14,
    200: 6, 210: 6,
    400: 7, 410: 7, 420: 7, 411: 7, 421: 7,
    430: 8, 431: 8, 432: 8, 490: 8,
    540: 12, 550: 12, 560: 12, 570: 12, 580: 12, 590: 12, 591: 12, 592: 12, 593: 12,
    610: 13, 611: 13, 640: 13,
    980: 10, 990: 10,
    70: 15, 80: 15,
}
#: Why some well-known codes are refused (others get a generic "unsupported").
G_REFUSED: dict[int, str] = {}
#: Why some well-known M-codes are refused.
M_REFUSED = {
    60: "pallet change (M60) is not supported",
}
M_GROUP = {0: 4, 1: 4, 2: 4, 30: 4, 6: 6, 3: 7, 4: 7, 5: 7, 19: 7, 7: 8, 8: 8, 9: 8,
           62: 5, 63: 5, 64: 5, 65: 5, 66: 5, 67: 5, 68: 5, 98: 11, 99: 11, 61: 6,
           70: 12, 71: 12, 72: 12, 73: 12,
           48: 9, 49: 9, 50: 9, 51: 9, 52: 9, 53: 9}  # overrides.py
M_GROUP.update(dict.fromkeys(range(100, 200), 10))  # user M-codes (usermcodes.py)
