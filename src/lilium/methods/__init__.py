"""SFO methods: POSEST-SFO (baseline)."""
