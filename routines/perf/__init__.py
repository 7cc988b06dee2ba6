"""Performance tools: the dataflow cost model, clock calibration, peers, timing, the chart."""
