"""The analyses behind the facade's functions of the same names, built on the public
statistics (allan, spectrum, stats, noise): a still log's events, warm-up and thermal
bias (on channels' rate columns); several sensors on one mount (align, hat, mount) and
a fleet of units (fleet); the phase statistics PDEV, MTIE, TIE rms (timefreq); and the
ADEV of a stream (allan_stream). Private: the public names are ``imunoise.events``,
``imunoise.align``, ... (each module's function, not the module)."""
