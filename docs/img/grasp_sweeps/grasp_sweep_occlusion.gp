set terminal pngcairo size 800,500 font ',11'
set output 'grasp_sweep_occlusion.png'
set title 'grasp success, 100 trials a point, seed 1, camera model'
set xlabel 'occlusion length (s)'
set ylabel 'held after the lift (%)'
set yrange [0:105]
set grid lc rgb '#dddddd'
set key below
plot 'grasp_sweep_occlusion.dat' index 0 using 1:2:3:4 with yerrorbars lc rgb '#1f77b4' pt 7 notitle, 'grasp_sweep_occlusion.dat' index 0 using 1:2 with lines lw 2 lc rgb '#1f77b4' title 'prediction (Burg)', 'grasp_sweep_occlusion.dat' index 1 using 1:2:3:4 with yerrorbars lc rgb '#ff7f0e' pt 7 notitle, 'grasp_sweep_occlusion.dat' index 1 using 1:2 with lines lw 2 lc rgb '#ff7f0e' title 'no prediction', 'grasp_sweep_occlusion.dat' index 2 using 1:2:3:4 with yerrorbars lc rgb '#2ca02c' pt 7 notitle, 'grasp_sweep_occlusion.dat' index 2 using 1:2 with lines lw 2 lc rgb '#2ca02c' title 'Kalman baseline'
