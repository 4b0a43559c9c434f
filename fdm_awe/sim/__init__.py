"""The simulation: the co-simulation loop (JSBSim glider + ground station), its compiled kernel,
the event table, flights with the autopilot, the paper plant and real-time pacing."""
