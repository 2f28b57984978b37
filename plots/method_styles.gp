# Written by `nhi list --gnuplot` (make figures) from the line style each method declares
# for its study entries (StudyEntry::style in its header): do not edit.  plots/style.gp
# loads it and defines the styles and other_ls() for labels that are not methods.
method_ls(label) = \
  label eq "dla a=0.5" ? 11 : \
  label eq "dla-sym a=0" ? 13 : \
  label eq "dla a=0.5+triple_jump" ? 12 : \
  label eq "rk4" ? 51 : \
  label eq "reference" ? 10 : \
  label eq "mp06" ? 21 : \
  label eq "mp06+triple_jump" ? 22 : \
  label eq "mp06+suzuki5" ? 23 : \
  label eq "mp06+order6" ? 24 : \
  label eq "discrete_gradient" ? 31 : \
  label eq "discrete_gradient+triple_jump" ? 32 : \
  label eq "dla-group a=0.5" ? 81 : \
  label eq "eps-cayley" ? 85 : \
  label eq "dla a=0" ? 15 : \
  label eq "dla a=0.25" ? 16 : \
  label eq "dla a=0.75" ? 17 : \
  label eq "dla a=1" ? 18 : \
  label eq "dla-sym a=0.25" ? 19 : \
  label eq "dla-sym a=0+triple_jump" ? 14 : \
  label eq "discrete_gradient+suzuki5" ? 33 : \
  label eq "discrete_gradient+order6" ? 34 : \
  label eq "discrete_gradient endpoint" ? 35 : \
  label eq "discrete_gradient endpoint+triple_jump" ? 36 : \
  label eq "discrete_gradient endpoint+suzuki5" ? 37 : \
  label eq "discrete_gradient endpoint+order6" ? 38 : \
  label eq "spark s=2" ? 41 : \
  label eq "spark s=3" ? 42 : \
  label eq "spark s=4" ? 43 : \
  label eq "rkf78" ? 61 : \
  label eq "dopri5" ? 62 : \
  other_ls(label)
