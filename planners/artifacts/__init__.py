"""Artifact fusion (CERBERUS SubT Final paper, section 3.5 "Artifacts scoring"):
onboard, camera detections located by rays into the robot's voxel map and fused
into tracks with a binary Bayes filter per class, Bluetooth and CO2 readings
clustered; at the base station, reports of all robots merged into candidates and a
submission policy against the report budget. Pure numpy; nothing of delve outside
``planners``.
"""
