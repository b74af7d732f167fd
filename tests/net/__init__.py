"""A car on the network: shares, remote drivers, the fleet (issue 66)."""
