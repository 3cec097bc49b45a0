"""Long-wave theory of the chain (Eqs 1, 2, 4 of Daraio et al. 2006, and for a power-law
contact F = A delta^n) and the exact discrete solitary wave. Imports only the foundation."""
