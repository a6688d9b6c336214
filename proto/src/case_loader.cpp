// placeholder until the case loader lands
