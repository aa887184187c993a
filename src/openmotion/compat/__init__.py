"""Vendor compatibility facades. `hctl1100`: the HCTL-1100 chip emulation; `aim104`: the
Arcom AIM104-MOTION-1 board (I/O map, interrupts, SYNC) and its MOTION_* library."""
