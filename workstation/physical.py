"""What phones measure, in one table (issues #55, #67): a value beyond is no measurement.

Session loading (:mod:`workstation.session.sanity`) drops a sample beyond its sensor's range
with a warning and refuses a stream with more than 5 % of them (a broken sensor or another
unit); radio-map files (:mod:`workstation.io.map_read`) refuse an RSS outside ``RSS_DBM`` or a
floor that is no floor, naming the file, column and row.
"""

from __future__ import annotations

#: per motion sensor: the largest magnitude a phone reports, and its unit
PHYSICAL = {
    "accelerometer": (157.0, "m/s²"),  # 16 g, where phones saturate
    "gyroscope": (70.0, "rad/s"),  # 4000 °/s, the widest range a phone has
    "magnetometer": (5000.0, "µT"),  # phones saturate at 1,200–4,900 µT (the Earth: 25–65)
}
#: a WiFi reading (dBm): far below any phone's floor … a transmitter's own power
RSS_DBM = (-150.0, 30.0)
#: a floor number: a whole number, within this of 0
MAX_FLOOR = 200
