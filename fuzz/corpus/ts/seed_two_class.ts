# a small univariate problem
@problemName tiny
@timeStamps false
@missing false
@univariate true
@equalLength true
@seriesLength 5
@classLabel true a b
@data
1.0,2.0,3.0,2.0,1.0:a
0.5,0.4,?,0.2,0.1:b
3,3,3,3,3:a
