"""Autopilot: reference path -> guidance (point-mass force inversion) -> attitude, speed and
thrust loops -> surfaces and throttle; phase logic for the pumping cycle; MAVLink-style modes."""
