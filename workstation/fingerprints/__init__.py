"""WiFi fingerprints (§V-C): radio maps and localization (:mod:`.localize`, eq. 21), the 1-NN
index (:mod:`.nn`), device RSS offsets (:mod:`.devices`), points on standby
(:mod:`.standby`), map quality (:mod:`.quality`) and the UJIIndoorLoc benchmark (:mod:`.uji`)."""
