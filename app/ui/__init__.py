"""The viser web page: page (server, layout, tabs), position_tab and bldc_tab, the case and its port, panels, worker."""
