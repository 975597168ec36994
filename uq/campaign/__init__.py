"""A floating lidar's campaign records corrected: each ten-minute record's turbulence
intensity freed of the platform's motion and of the lidar's own filtering, with its
uncertainty and 95 % interval, the motion's bias of the mean speed, per-bin statistics
and errors against a reference, and the ``uq campaign`` report.

The physics the correction stands on (the spectral path, the time-resolved measurement
model, the Monte Carlo records) is reached through :mod:`uq.campaign.adapter` alone.
"""
