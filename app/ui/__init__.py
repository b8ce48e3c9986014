"""The viser web page: session, input fields, results, replay, scene, tuning, log and BLDC tabs, worker."""
